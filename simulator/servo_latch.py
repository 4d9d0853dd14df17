"""The emulated servos' latched hardware errors, kept between rti-rig commands.

A real X-series servo keeps its Hardware Error Status (70) while it stays powered: after a
shutdown "REBOOT is the only method to reset Torque Enable(64) to '1'" (ROBOTIS e-manual,
Shutdown (63); Hardware Error Status (70)). Each rti-rig command
builds a fresh emulator, so an overload met by ``rti-rig run`` was gone by the next command and
the documented recovery, ``rti-rig check ARM.toml --reboot-faulted``, found "no hardware
fault: not rebooted": it could not be rehearsed.

This models the emulated chain staying powered between commands: the errors latched by a
command are written to a small state file, read back by the next command on the same rig, and
cleared by a Reboot instruction (the file is removed once no servo has an error). Only the
error bits are kept (and, through them, a shutdown's torque off); positions, RAM settings and
the like start from power-on, a simplification.

The file is keyed by the rig config's absolute path, so another config meets a fresh chain;
the same config with its ``[[emulator.faults]]`` edited (the obstruction cleared, as the
error advises before the reboot) is the same chain, its error still latched. It lives
in a per-user folder: ``$RTI_RIG_EMULATOR_STATE_DIR`` if set, else
``$XDG_RUNTIME_DIR/rti-rig/emulated-servos``, else ``<temp>/rti-rig-<uid>/emulated-servos``.
To "power-cycle" the emulated servos, delete that file (or the folder).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shlex
import tempfile
import warnings
from pathlib import Path

from rti_rig.core.state_files import replace_text

#: Overrides where the state files are kept (a test's own folder, say).
STATE_DIR_ENV = "RTI_RIG_EMULATOR_STATE_DIR"


def state_dir() -> Path:
    """The per-user folder of the emulated servos' state files (see the module docstring)."""
    given = os.environ.get(STATE_DIR_ENV)
    if given:
        return Path(given)
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime and Path(runtime).is_dir():
        return Path(runtime) / "rti-rig" / "emulated-servos"
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    return Path(tempfile.gettempdir()) / f"rti-rig-{uid}" / "emulated-servos"


class LatchedErrors:
    """The state file of one emulated chain: servo id -> latched Hardware Error Status bits."""

    def __init__(self, config_path: Path) -> None:
        self.config_path = Path(config_path).resolve()
        # keyed by the config's path alone, not its [emulator] section too: the error's advice
        # is "clear the obstruction; then run rti-rig check … --reboot-faulted", and on an
        # emulated arm the obstruction is cleared by taking its [[emulator.faults]] out; a key
        # that changed with them met a fresh chain, "no hardware fault: not rebooted"
        digest = hashlib.sha256(str(self.config_path).encode()).hexdigest()[:16]
        self.path = state_dir() / f"{self.config_path.stem}-{digest}.json"

    def power_cycle_said(self) -> str:
        """How a fault's advice tells the user to power-cycle this emulated chain: delete its
        state file (path shell-quoted, to be pasted).

        Why: the advice said "switch the servos' power off and on", which an emulated chain
        has no switch for; its errors outlive the command in this file, and deleting it is
        what clears them (as ``rti-rig check RIG.toml --reboot-faulted`` does)."""
        return (
            f"delete {shlex.quote(str(self.path))} (where the emulated servos' latched errors "
            "are kept: their power off and on)"
        )

    def load(self) -> dict[int, int]:
        """The errors the chain still has from an earlier command; {} if none or unreadable.

        Why unreadable is {}: the file is the emulator's own scratch state, not the user's
        data; a damaged one is a chain that was power-cycled, not an error to stop a run on."""
        try:
            raw = json.loads(self.path.read_text(encoding="utf-8"))
            errors = raw["hardware_error_status"]
            return {int(k): int(v) & 0xFF for k, v in errors.items() if int(v) & 0xFF}
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return {}

    def save(self, errors: dict[int, int]) -> None:
        """Record the chain's errors now (atomically); no error left removes the file.

        Why a file that cannot be written is a warning, not an error: this is called from
        inside the emulated bus as a status packet goes out, so an OSError here (a full disk,
        a state folder another user made in the shared temp folder) reached the driver as its
        serial port failing, "check that the arm's USB adapter is still plugged in", and the
        servo's own fault went unsaid. Unkept, the chain is met by the next command as if
        power-cycled, which the warning says (the console prints it as a note)."""
        try:
            self._write(errors)
        except OSError as exc:
            warnings.warn(
                f"the emulated servos' hardware error state could not be kept in {self.path} "
                f"({exc}): the next command on this rig meets them as if power-cycled; set "
                f"{STATE_DIR_ENV} to a writable folder to keep it",
                RuntimeWarning,
                stacklevel=2,
            )

    def _write(self, errors: dict[int, int]) -> None:
        """:meth:`save`'s file work, which may raise OSError."""
        latched = {str(k): v for k, v in sorted(errors.items()) if v}
        if not latched:
            with contextlib.suppress(FileNotFoundError):
                self.path.unlink()
            return
        body = json.dumps(
            {
                "config": str(self.config_path),
                "hardware_error_status": latched,
                "note": "emulated servos kept powered between rti-rig commands; "
                "delete this file to power-cycle them",
            },
            indent=1,
        )
        replace_text(self.path, body)
