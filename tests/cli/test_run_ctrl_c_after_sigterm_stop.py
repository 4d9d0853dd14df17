"""A Ctrl-C that lands as ``run``, stopped by SIGTERM, is leaving (its handlers put back, the
143 on its way out) does not turn the stop into a Ctrl-C's: the words said SIGTERM, and the
exit status says it too (143), with one line for the Ctrl-C.

Before, Python's KeyboardInterrupt was back in place once the capture's handlers were
undone (``_execute``'s ``put_back``), and a Ctrl-C 0.1-0.3 s after the SIGTERM replaced the
exit in the unwinding: "Emergency stop (SIGTERM)" said, "rti-rig: stopped (Ctrl-C)", exit
130. Through the console entry in a child process; no timing: the SIGTERM is raised in the
child as its second image is committed, the Ctrl-C right after ``put_back`` gives SIGINT
back to Python's handler (the first moment it could escape).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO

_CHILD = r"""
import signal, sys
import rti_rig.cli.session as cli_session
from rti_rig.runtime.session import SessionFolder

real_write, real_put_back, sent = SessionFolder.write_step, cli_session.put_back, []

def write_step(self, index, *args, **kwargs):
    record = real_write(self, index, *args, **kwargs)
    if index == 1:
        signal.raise_signal(signal.SIGTERM)  # a service manager's stop, between images
    return record

def put_back(previous):
    real_put_back(previous)
    if previous.get(signal.SIGINT) is signal.default_int_handler and not sent:
        sent.append(1)
        signal.raise_signal(signal.SIGINT)  # the user's Ctrl-C, as the stop's exit unwinds

SessionFolder.write_step = write_step
cli_session.put_back = put_back
sys.argv = ["rti-rig", *sys.argv[1:]]
from rti_rig.launch import main
main()
"""


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_as_a_sigterm_stop_ends_keeps_its_143(tmp_path: Path) -> None:
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "4", "--out", str(out)]
    result = subprocess.run(
        [sys.executable, "-c", _CHILD, *argv, "--no-verdict"],
        capture_output=True,
        env={**os.environ, "PYTHONPATH": str(REPO)},
        timeout=600,
    )
    said = " ".join(result.stderr.decode("utf-8", "replace").split())
    assert "Emergency stop (SIGTERM)" in said, said
    assert "Ctrl-C as the command was ending: the stop by SIGTERM stands (exit 143)" in said
    assert "stopped (Ctrl-C)" not in said and "Traceback" not in said, said
    assert result.returncode == 143, said
