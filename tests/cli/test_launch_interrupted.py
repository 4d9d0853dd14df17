"""A Ctrl-C while `rti-rig` is still importing its command line ends without a traceback."""

import subprocess
import sys

# Raise KeyboardInterrupt exactly where a Ctrl-C in the first tenths of a second lands: in the
# import of the command line, before any command runs.
_INTERRUPT_THE_IMPORT = """
import sys

class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == "rti_rig.cli":
            raise KeyboardInterrupt
        return None

sys.meta_path.insert(0, Interrupt())
from rti_rig.launch import main
main()
"""


def test_ctrl_c_during_the_import_says_nothing_was_done() -> None:
    done = subprocess.run(
        [sys.executable, "-c", _INTERRUPT_THE_IMPORT], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 130, done.stderr
    assert "Traceback" not in done.stderr
    assert "stopped while starting" in done.stderr and "nothing was done" in done.stderr


def test_the_installed_script_starts_through_the_quiet_entry_point() -> None:
    from importlib.metadata import entry_points

    (script,) = [e for e in entry_points(group="console_scripts") if e.name == "rti-rig"]
    assert script.value == "rti_rig.launch:main"


def test_python_dash_m_runs_the_command_line() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "rti_rig", "--help"], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert "run" in done.stdout and "plan" in done.stdout


# A Ctrl-C inside a command that does not handle it (here export-lp, in its own import): typer
# turns it into exit 130 without a word; the entry point says it stopped.
_INTERRUPT_A_COMMAND = """
import sys

class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == "rti_rig.app.usecases.export":
            raise KeyboardInterrupt
        return None

sys.argv = ["rti-rig", "export-lp", "nowhere", "--out", "nowhere.lp"]
sys.meta_path.insert(0, Interrupt())
from rti_rig.launch import main
main()
"""


def test_ctrl_c_in_a_command_that_does_not_handle_it_is_said() -> None:
    done = subprocess.run(
        [sys.executable, "-c", _INTERRUPT_A_COMMAND], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 130, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.strip() == "rti-rig: stopped (Ctrl-C)"


def test_a_command_s_own_exit_130_is_not_said_twice() -> None:
    """run's own "Session cancelled" exit is 130 after its message: no second line."""
    from rti_rig.launch import _from_keyboard_interrupt

    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise SystemExit(130) from None
    except SystemExit as own:
        assert not _from_keyboard_interrupt(own)
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as e:
            raise SystemExit(130) from e
    except SystemExit as typers:
        assert _from_keyboard_interrupt(typers)


_INTERRUPT_THE_RIG_OPENING = """
import sys

class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == "rti_rig.app.compose":  # imported as the rig is built
            raise KeyboardInterrupt
        return None

sys.argv = ["rti-rig", "run", sys.argv[1], "--out", sys.argv[2], "--lights", "4"]
sys.meta_path.insert(0, Interrupt())
from rti_rig.launch import main
main()
"""


def test_ctrl_c_while_the_rig_opens_says_nothing_was_captured(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """It had exited 130 with no word at all."""
    from pathlib import Path

    cfg = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
    out = tmp_path / "s"
    done = subprocess.run(
        [sys.executable, "-c", _INTERRUPT_THE_RIG_OPENING, str(cfg), str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 130, done.stderr
    text = " ".join(done.stderr.split())
    assert "Traceback" not in text
    assert (
        f"Stopped (Ctrl-C) before the first image: nothing was captured or written to {out}" in text
    )
    assert not out.exists()
