"""A Ctrl-C a command handles exits 130 under ``python -m rti_rig``, never by SIGINT (-2).

CPython marks a KeyboardInterrupt "unhandled" when it passes through code run from a string
(``exec``/``eval``: the methods of a dataclass or namedtuple made as a module is imported),
even when the command catches it; under ``python -m`` nothing clears the mark, and the
process killed itself with SIGINT at exit, after its own "Stopped (Ctrl-C)" and exit 130: a
test's parent saw -2 (found by sending Ctrl-C to ``python -m rti_rig fit`` at swept delays:
5 of 28). Here the Ctrl-C is a real SIGINT raised from such a string, as ``fit`` lazily
imports its use case (no race). The wrapper module is run with ``-m`` itself, which is what
takes CPython's ``-m`` path, and runs ``rti_rig`` as ``python -m rti_rig`` does.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"

_CUT_FIT = """
import runpy, signal, sys

signal.signal(signal.SIGINT, signal.default_int_handler)
signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})

class CtrlCInAString:
    fired = False

    def find_spec(self, name, path=None, target=None):
        if name == "rti_rig.app.usecases.fit" and not CtrlCInAString.fired:
            CtrlCInAString.fired = True
            sys.stderr.write("CUT\\n")
            sys.stderr.flush()
            exec("import signal; signal.raise_signal(signal.SIGINT)")
        return None

sys.meta_path.insert(0, CtrlCInAString())
runpy.run_module("rti_rig", run_name="__main__", alter_sys=True)
"""


def test_a_ctrl_c_landing_in_code_run_from_a_string_exits_130(tmp_path: Path) -> None:
    (tmp_path / "cut_fit_in_a_string.py").write_text(_CUT_FIT)
    out = tmp_path / "fit"
    done = subprocess.run(
        [sys.executable, "-m", "cut_fit_in_a_string", "fit", str(ACQ), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,  # where -m finds the wrapper
    )
    text = done.stdout + done.stderr
    assert done.stderr.startswith("CUT\n"), text  # the Ctrl-C landed in the string's code
    assert "Traceback" not in text, text
    assert "Stopped (Ctrl-C) before the fit finished" in " ".join(text.split()), text
    assert done.returncode == 130, (done.returncode, text)
    assert not out.exists()
