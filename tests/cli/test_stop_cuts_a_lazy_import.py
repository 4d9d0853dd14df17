"""A Ctrl-C that cuts a command's lazy import of numpy is said as a stop, not a traceback.

``fit`` sets its stop handling, then imports OpenCV and numpy. A Ctrl-C landing while numpy's C
core initialises leaves numpy unloadable for the rest of the process; the stop's handler then
imported the controller (which imports numpy) to ask whether the stop was an EmergencyStop,
and the user got "ImportError: cannot load module more than once per process" with two
tracebacks and exit 1 (found by sending Ctrl-C to ``rti-rig fit`` at swept delays, about one
in ten near two seconds). Here the Ctrl-C is a real SIGINT, raised at that point (no race):
as the core's initialisation imports ``numpy.dtypes``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"

#: The child: a Ctrl-C as a shell gives it (default handler, unblocked), raised once, as
#: ``numpy.dtypes`` is first imported (inside the init of numpy's C core); "CUT" said then.
_CUT_IN_NUMPY = """
import signal, sys

signal.signal(signal.SIGINT, signal.default_int_handler)
signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

class CtrlCInNumpysCore:
    fired = False

    def find_spec(self, name, path=None, target=None):
        if name == "numpy.dtypes" and not CtrlCInNumpysCore.fired:
            CtrlCInNumpysCore.fired = True
            sys.stderr.write("CUT\\n")
            sys.stderr.flush()
            signal.raise_signal(signal.SIGINT)
        return None

sys.argv = ["rti-rig", *sys.argv[1:]]
sys.meta_path.insert(0, CtrlCInNumpysCore())
from rti_rig.launch import main
main()
"""


def test_a_ctrl_c_that_cuts_numpys_import_in_fit_is_said_as_a_stop(tmp_path: Path) -> None:
    out = tmp_path / "fit"
    done = subprocess.run(
        [sys.executable, "-c", _CUT_IN_NUMPY, "fit", str(ACQ), "--out", str(out), "--no-qa"],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=REPO,
    )
    text = done.stdout + done.stderr
    assert done.stderr.startswith("CUT\n"), text  # the Ctrl-C landed inside numpy's import
    assert done.returncode == 130, text
    assert "Traceback" not in text and "ImportError" not in text, text
    said = " ".join(text.split())
    assert "Stopped (Ctrl-C) before the fit finished: nothing it wrote was left in" in said, said
    assert not out.exists()


def test_a_stop_is_told_from_its_exception_without_importing_the_controller() -> None:
    """What the fix rests on: ``stop_signal`` of a Ctrl-C or a SIGTERM imports nothing, and
    an EmergencyStop is still told by its own signal."""
    code = """
import signal, sys
from rti_rig.cli.stopping import Terminated, stop_signal
assert stop_signal(KeyboardInterrupt()) == signal.SIGINT
assert stop_signal(Terminated()) == signal.SIGTERM
assert "rti_rig.runtime.controller" not in sys.modules and "numpy" not in sys.modules
from rti_rig.runtime.controller import EmergencyStop
assert stop_signal(EmergencyStop(signal.SIGTERM)) == signal.SIGTERM
print("ok")
"""
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=REPO
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stdout + done.stderr
