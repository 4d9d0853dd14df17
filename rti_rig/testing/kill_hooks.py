"""Make a dry-run session die (SIGKILL) at a chosen stage of a chosen step.

This is how the resume tests and the fault campaign reproduce the worst interruption there is:
no ``finally``, no flush, a half-written file. Run as a module it installs the hooks and then
runs the ``rti-rig`` command line with the remaining arguments::

    python -m rti_rig.testing.kill_hooks STAGE K run RIG.toml --out DIR --lights 8

Stages: ``before_light``, ``after_light``, ``during_capture``, ``during_write`` (half a TIFF in
its temporary file), ``between_files`` (TIFF renamed, JPEG not written), ``before_journal`` (both
files complete, journal line not written), ``after_record`` (the step's record file
``records/BASE.json`` written, its journal line not), ``after_journal`` (the journal line
written, nothing after it), and ``stall`` (no kill: capture K blocks for up to 60 s of real
time, so that another process can signal the run at a known step). One stage is a batch fit's
(``fit S1 S2 --out ROOT``), not a run's: ``refit_swap`` dies between the two renames of its
K-th refit (the earlier fit set aside, the new one not yet in its place), and ``fit_hold``
(no kill) holds a batch's K-th session just before it writes its ``fit.json`` into its
partial folder, for as long as the file the environment's ``RTI_RIG_HOLD`` names exists
(at most 300 s), having created ``$RTI_RIG_HOLD.reached``: another batch is then run into
the same ``--out`` at a known moment.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

STAGES = (
    "before_light",
    "after_light",
    "during_capture",
    "during_write",
    "between_files",
    "before_journal",
    "after_record",
    "after_journal",
    "stall",
    "refit_swap",
    "fit_hold",
)


def install(stage: str, k: int) -> None:
    """Patch the simulated devices and the session writer so the process dies at step ``k``."""
    import rti_rig.core.image_files as image_files
    import rti_rig.runtime.session as session
    import rti_rig.simulator.sim_camera as sim_camera
    import rti_rig.simulator.sim_lights as sim_lights

    if stage not in STAGES:
        raise SystemExit(f"unknown stage {stage!r}; choose from {', '.join(STAGES)}")
    counts = {"light": 0, "capture": 0, "write": 0, "journal": 0, "record": 0, "line": 0}

    def die() -> None:
        os.kill(os.getpid(), signal.SIGKILL)

    real_light = sim_lights.SimulatedDome.light
    real_move = sim_lights.SimulatedArm.move_to
    real_capture = sim_camera.SimulatedCamera.capture
    real_write = image_files._atomic_write
    real_asdict = session.asdict
    real_record = session.SessionFolder._write_step_record
    real_append = session.SessionFolder._append_journal

    def lit(call, *args):  # type: ignore[no-untyped-def]
        if stage == "before_light" and counts["light"] == k:
            die()
        result = call(*args)
        if stage == "after_light" and counts["light"] == k:
            die()
        counts["light"] += 1
        return result

    def light(self, index, intensity=1.0):  # type: ignore[no-untyped-def]
        return lit(real_light, self, index, intensity)

    def move_to(self, direction):  # type: ignore[no-untyped-def]
        return lit(real_move, self, direction)

    def capture(self, exposure_s):  # type: ignore[no-untyped-def]
        if stage == "stall" and counts["capture"] == k:
            deadline = time.monotonic() + 60.0
            while time.monotonic() < deadline:  # a signal handler's exception ends this
                time.sleep(0.05)
        frame = real_capture(self, exposure_s)
        if stage == "during_capture" and counts["capture"] == k:
            die()
        counts["capture"] += 1
        return frame

    def atomic_write(path: Path, data: bytes) -> str:
        n = counts["write"]
        counts["write"] += 1
        if stage == "during_write" and n == 2 * k:
            with open(path.with_name(f".{path.name}.partial"), "wb") as fh:
                fh.write(data[: len(data) // 2])
            die()
        if stage == "between_files" and n == 2 * k + 1:
            die()
        return real_write(path, data)

    def asdict(obj):  # type: ignore[no-untyped-def]
        if stage == "before_journal" and isinstance(obj, session.StepRecord):
            if counts["journal"] == k:
                die()
            counts["journal"] += 1
        return real_asdict(obj)

    def after(call, stage_here: str, count: str):  # type: ignore[no-untyped-def]
        def write(self, *args):  # type: ignore[no-untyped-def]
            call(self, *args)
            if stage == stage_here and counts[count] == k:
                die()
            counts[count] += 1

        return write

    folder = session.SessionFolder
    folder._write_step_record = after(real_record, "after_record", "record")  # type: ignore[method-assign]
    folder._append_journal = after(real_append, "after_journal", "line")  # type: ignore[method-assign]
    sim_lights.SimulatedDome.light = light  # type: ignore[method-assign]
    sim_lights.SimulatedArm.move_to = move_to  # type: ignore[method-assign]
    sim_camera.SimulatedCamera.capture = capture  # type: ignore[method-assign]
    image_files._atomic_write = atomic_write
    session.asdict = asdict  # type: ignore[assignment]
    if stage == "refit_swap":
        _die_in_refit_swap(k, die)
    if stage == "fit_hold":
        _hold_before_fit_json(k)


def _hold_before_fit_json(k: int) -> None:
    """Hold the ``k``-th ``fit.json`` written into a batch's partial folder while the file
    ``$RTI_RIG_HOLD`` exists (see the module docstring)."""
    real_write_text = Path.write_text
    hold = Path(os.environ["RTI_RIG_HOLD"])
    seen = [0]

    def write_text(self: Path, *args: Any, **kwargs: Any) -> int:
        if self.name == "fit.json" and self.parent.name.endswith(".partial"):
            if seen[0] == k:
                Path(f"{hold}.reached").touch()
                deadline = time.monotonic() + 300.0
                while hold.exists() and time.monotonic() < deadline:
                    time.sleep(0.05)
            seen[0] += 1
        return real_write_text(self, *args, **kwargs)

    Path.write_text = write_text  # type: ignore[method-assign]


def _die_in_refit_swap(k: int, die: Callable[[], None]) -> None:
    """Die right after the ``k``-th rename that sets a batch's earlier fit aside."""
    from rti_rig.app.usecases.fit_attempts import AttemptFolder, Kind

    real_rename = Path.rename
    renamed = [0]

    def rename(self: Path, target: Any) -> Path:
        result = real_rename(self, target)
        attempt = AttemptFolder.parse(Path(target).name)
        if attempt is not None and attempt.kind is Kind.EARLIER:
            if renamed[0] == k:
                die()
            renamed[0] += 1
        return result

    Path.rename = rename  # type: ignore[method-assign]


def popen_session(
    stage: str, k: int, config: Path | str, out: Path | str, lights: int
) -> subprocess.Popen[bytes]:
    """Start ``rti-rig run CONFIG --out OUT --lights LIGHTS`` in a child process that dies at
    ``stage`` of step ``k`` (see the module docstring); stdout and stderr are piped."""
    return popen_argv(stage, k, ["run", str(config), "--out", str(out), "--lights", str(lights)])


def popen_argv(stage: str, k: int, cli_args: list[str]) -> subprocess.Popen[bytes]:
    """Start ``rti-rig CLI_ARGS…`` (``run --resume DIR``, say) in a child process that dies
    at ``stage`` of step ``k``, counted from this process's first step; stdout and stderr are
    piped."""
    repo = Path(__file__).resolve().parent.parent
    env = {**os.environ, "PYTHONPATH": str(repo)}
    argv = [sys.executable, "-m", "rti_rig.testing.kill_hooks", stage, str(k), *cli_args]
    return subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)


USAGE = (
    "usage: python -m rti_rig.testing.kill_hooks STAGE K RTI-RIG-ARGS…\n"
    "  runs `rti-rig RTI-RIG-ARGS…` (e.g. run RIG.toml --out DIR --lights 8) and SIGKILLs it at\n"
    "  STAGE of its step K (0-based); STAGE is one of: " + ", ".join(STAGES)
)


def main(argv: list[str]) -> None:
    """Install the hooks, then run the command line; a usage line (exit 1) for ``--help`` or
    arguments it cannot take (it had ended in a ValueError traceback)."""
    from rti_rig.cli import app

    if len(argv) < 3 or argv[0] in ("-h", "--help") or not argv[1].isdigit():
        raise SystemExit(USAGE)
    stage, k, *cli_args = argv
    install(stage, int(k))
    app(cli_args)


if __name__ == "__main__":
    main(sys.argv[1:])
