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
