"""The emulated servos' powered state (latched errors, torque, pose, RAM), kept between commands.

A real X-series servo keeps its Hardware Error Status (70) while it stays powered: after a
shutdown "REBOOT is the only method to reset Torque Enable(64) to '1'" (ROBOTIS e-manual,
Shutdown (63); Hardware Error Status (70)). Each rti-rig command
builds a fresh emulator, so an overload met by ``rti-rig run`` was gone by the next command and
the documented recovery, ``rti-rig check ARM.toml --reboot-faulted``, found "no hardware
fault: not rebooted": it could not be rehearsed.

This models the emulated chain staying powered between commands: what each servo holds (its
control table: Torque Enable, Goal Position, profiles, LED, Status Return Level, the Hardware
Error Status, and the EEPROM area a connect synchronised; a shutdown; where the joint comes to
rest) is written to a small state file, read back by the next command on the same rig. A real
chain keeps all of it while powered: RAM is "reset to initial values when the power is reset"
and only then (ROBOTIS e-manual, X-series control table, Area), so a command that left torque
on (``torque_policy = "hold"``, or ``"release_on_close"`` away from the park pose, or a crash)
leaves the next one a holding arm, whose EEPROM is then locked ("Data in the EEPROM Area can
only be written when the value of Torque Enable(64) is cleared to '0'"). Only the errors had
been kept, each command meeting servos otherwise as at power-on: the paths a real arm takes
after a session that kept its torque on were never rehearsed. A Reboot resets the RAM area
(errors included) as on a servo. Deleting the file is the power cycle: the next command meets
the chain at power-on, its RAM at its initial values (torque off, no error latched), its
EEPROM area kept and each joint where it rested, a loaded joint that held under torque fallen
to its stop. The EEPROM is kept in a second file beside it (``….eeprom.json``), which a
power cycle leaves; deleting both is a factory-fresh chain as the config describes it at the
park pose. (The one file had held both: its deletion had reset the EEPROM, position limits
a connect wrote among it, and moved the joints back to the park pose, as no power cycle does.)

The file is keyed by the rig config's absolute path, so another config meets a fresh chain;
the same config with its ``[[emulator.faults]]`` edited (the obstruction cleared, as the
error advises before the reboot) is the same chain, its error still latched. It lives
in a per-user folder: ``$RTI_RIG_EMULATOR_STATE_DIR`` if set, else
``$XDG_RUNTIME_DIR/rti-rig/emulated-servos``, else ``<temp>/rti-rig-<uid>/emulated-servos``.
To "power-cycle" the emulated servos, delete that file (the EEPROM file beside it stays);
delete the folder for factory-fresh servos.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
import warnings
from pathlib import Path
from typing import Any

from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.core.state_files import replace_text
from rti_rig.simulator import dynamixel_table as tbl

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
    """The state file of one emulated chain: each servo's powered state (its latched Hardware
    Error Status bits among them)."""

    def __init__(self, config_path: Path) -> None:
        self.config_path = Path(config_path).resolve()
        # keyed by the config's path alone, not its [emulator] section too: the error's advice
        # is "clear the obstruction; then run rti-rig check … --reboot-faulted", and on an
        # emulated arm the obstruction is cleared by taking its [[emulator.faults]] out; a key
        # that changed with them met a fresh chain, "no hardware fault: not rebooted"
        digest = hashlib.sha256(str(self.config_path).encode()).hexdigest()[:16]
        self.path = state_dir() / f"{self.config_path.stem}-{digest}.json"
        #: what outlives a power cycle (the EEPROM area, the rest pose): kept apart, so that
        #: deleting :attr:`path` (the power cycle) leaves it
        self.eeprom_path = state_dir() / f"{self.config_path.stem}-{digest}.eeprom.json"

    def power_cycle_said(self) -> str:
        """How a fault's advice tells the user to power-cycle this emulated chain: delete its
        state file (path shell-quoted, to be pasted).

        Why: the advice said "switch the servos' power off and on", which an emulated chain
        has no switch for; its errors outlive the command in this file, and deleting it is
        what clears them (as ``rti-rig check RIG.toml --reboot-faulted`` does)."""
        return (
            f"delete {shell_word(str(self.path))} (where the emulated servos' powered state "
            "and latched errors are kept: their power off and on)"
        )

    def load_state(self) -> dict[int, dict[str, Any]]:
        """Each servo's powered state an earlier command left (``EmulatedServo.powered_state``);
        {} if none or unreadable (as :meth:`load` says why)."""
        try:
            raw = json.loads(self.path.read_text(encoding="utf-8"))
            servos = raw["servos"]
            return {int(k): dict(v) for k, v in servos.items()}
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return {}

    def save_state(self, states: dict[int, dict[str, Any]]) -> None:
        """Record every servo's powered state now (atomically): the chain stays powered, so
        the file stays, errors or none, until it is deleted (the power cycle). A file that
        cannot be written is a warning, as :meth:`_unkept` says why."""
        # by the ID each servo answers at (the states go by place in the chain), two sharing
        # an ID being one entry with both servos' bits
        errors: dict[str, int] = {}
        for v in states.values():
            table = bytes.fromhex(v["table"])
            key = str(table[tbl.ID.address])
            errors[key] = errors.get(key, 0) | table[tbl.HARDWARE_ERROR_STATUS.address]
        self._save(
            self.path,
            states,
            "emulated servos kept powered between rti-rig commands; "
            "delete this file to power-cycle them",
            "powered state (torque, pose, latched errors)",
            "the next command on this rig meets them as if power-cycled",
            hardware_error_status={k: v for k, v in errors.items() if v},
        )

    def forget_powered(self) -> None:
        """The chain lost its supply: delete the powered state's file (the power cycle), so
        the next command meets the servos at power-on, never as still powered. A file that
        cannot be deleted is a warning, as :meth:`_unkept` says."""
        try:
            self.path.unlink(missing_ok=True)
        except OSError as exc:
            self._unkept(
                self.path,
                "loss of power",
                "the next command on this rig may meet them as still powered",
                exc,
            )

    def load_eeprom(self) -> dict[int, dict[str, Any]]:
        """Each servo's EEPROM and rest pose as kept through a power cycle
        (``EmulatedServo.eeprom_state``); {} if none or unreadable (a factory-fresh chain)."""
        try:
            raw = json.loads(self.eeprom_path.read_text(encoding="utf-8"))
            return {int(k): dict(v) for k, v in raw["servos"].items()}
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return {}

    def save_eeprom(self, states: dict[int, dict[str, Any]]) -> None:
        """Record what each servo keeps through a power cycle (atomically); a file that
        cannot be written is a warning, as :meth:`_unkept` says."""
        self._save(
            self.eeprom_path,
            states,
            "emulated servos' EEPROM and rest pose, kept through a power cycle "
            "(deleting the other file); delete this one too for factory-fresh servos",
            "EEPROM area and rest pose",
            "after a power cycle (deleting the other file) they are met factory-fresh",
        )

    def _save(
        self,
        path: Path,
        states: dict[int, dict[str, Any]],
        note: str,
        what: str,
        lost: str,
        **extra: Any,
    ) -> None:
        """Write one of the two state files (``extra``: its fields beside the servos'). One
        writer for both: :meth:`save_state` and :meth:`save_eeprom` had been two copies."""
        body = json.dumps(
            {
                "config": str(self.config_path),
                **extra,
                "servos": {str(k): v for k, v in sorted(states.items())},
                "note": note,
            },
            indent=1,
        )
        try:
            replace_text(path, body)
        except OSError as exc:
            self._unkept(path, what, lost, exc)

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

    def _unkept(self, path: Path, what: str, lost: str, exc: OSError) -> None:
        """The warning of a state file (``path``, holding the servos' ``what``; ``lost``: what
        follows) that could not be written, naming that file (the EEPROM file's had been said
        to be the powered state's, the other file).

        Why a warning, not an error: the state is saved from inside the emulated bus as a
        status packet goes out, so an OSError here (a full disk, a state folder another user
        made in the shared temp folder) reached the driver as its serial port failing, "check
        that the arm's USB adapter is still plugged in", and the servo's own fault went
        unsaid. Unkept, the chain is met by the next command as if power-cycled, which the
        warning says (the console prints it as a note)."""
        warnings.warn(
            f"the emulated servos' {what} could not be kept in {shown_path(path)} ({exc}): {lost}; "
            f"set {STATE_DIR_ENV} to a writable folder to keep it",
            RuntimeWarning,
            stacklevel=4,  # the caller of save_state / save_eeprom
        )
