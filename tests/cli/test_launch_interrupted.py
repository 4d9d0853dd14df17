"""A Ctrl-C that no command handles ends in one line and exit 130, never a traceback or silence.

The Ctrl-C is raised where it would land, by a finder that interrupts the import of a named
module: the command line's own import (the first tenths of a second), a command's lazy import
(a command with nothing to make safe), or the composition root (while a session's rig opens).
"""

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

_INTERRUPTED_RUN = """
import sys

module, argv = sys.argv[1], sys.argv[2:]

class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == module:
            raise KeyboardInterrupt
        return None

sys.argv = ["rti-rig", *argv]
sys.meta_path.insert(0, Interrupt())
from rti_rig.launch import main
main()
"""


def interrupted(module: str, *argv: str) -> subprocess.CompletedProcess[str]:
    """``rti-rig ARGV`` with a Ctrl-C at the import of ``module``."""
    return subprocess.run(
        [sys.executable, "-c", _INTERRUPTED_RUN, module, *argv],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_ctrl_c_during_the_import_says_nothing_was_done() -> None:
    done = interrupted("rti_rig.cli", "--help")
    assert done.returncode == 130, done.stderr
    assert "Traceback" not in done.stderr
    assert "stopped while starting" in done.stderr and "nothing was done" in done.stderr


def test_the_installed_script_starts_through_the_quiet_entry_point() -> None:
    from importlib.metadata import entry_points

    (script,) = [e for e in entry_points(group="console_scripts") if e.name == "rti-rig"]
    assert script.value == "rti_rig.launch:main"


@pytest.mark.parametrize("module", ["rti_rig", "rti_rig.launch"])
def test_python_dash_m_runs_the_command_line(module: str) -> None:
    """Also ``python -m rti_rig.launch``, the entry point's module: it had exited 0 having
    done nothing (no ``__main__`` guard), so a command run that way seemed to succeed."""
    done = subprocess.run(
        [sys.executable, "-m", module, "--help"], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert "run" in done.stdout and "plan" in done.stdout


def test_ctrl_c_in_a_command_that_does_not_handle_it_is_said() -> None:
    """typer turns it into exit 130 without a word; the entry point says it stopped."""
    done = interrupted("rti_rig.app.usecases.export", "export-lp", "nowhere", "--out", "x.lp")
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


def test_ctrl_c_while_the_rig_opens_says_nothing_was_captured(tmp_path: Path) -> None:
    """It had exited 130 with no word at all."""
    cfg = REPO / "rig_configs" / "simulated_dome.toml"
    out = tmp_path / "s"
    done = interrupted("rti_rig.app.compose", "run", str(cfg), "--out", str(out), "--lights", "4")
    assert done.returncode == 130, done.stderr
    text = " ".join(done.stderr.split())
    assert "Traceback" not in text
    assert (
        f"Stopped (Ctrl-C) before the first image: nothing was captured or written to {out}" in text
    )
    assert not out.exists()


def test_ctrl_c_during_the_import_exits_130_when_stderr_cannot_be_written() -> None:
    """Its one line's failed write (``2>/dev/full``) had raised, and the process exited 1."""
    import pytest

    if not Path("/dev/full").exists():
        pytest.skip("needs Linux's /dev/full")
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [sys.executable, "-c", _INTERRUPTED_RUN, "rti_rig.cli", "--help"],
            stdout=subprocess.PIPE,
            stderr=full,
            text=True,
            timeout=120,
        )
    assert done.returncode == 130, done.stdout
