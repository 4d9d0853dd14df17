"""A SIGTERM or Ctrl-C between a session's opening and its capture: a stop, said and closed.

The opening's SIGTERM handler was taken away before the capture's was set: a SIGTERM there
met the default action (the process ended at once, exit status -15, no word; a Ctrl-C there
exited 130, no word; a resume had just set unverified files aside in recovered/ and said
nothing more). It is now held until
the capture's handler is in place, which stops the session before its first image, closes
the rig and says so (exit 143). The signal is sent from inside the process at that very
point (no timing involved).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]

#: ``rti-rig`` with a SIGTERM sent to itself just after the session opened (the command's
#: hand-over to the capture), before the capture's handlers are set
STOP_AT_HAND_OVER = """
import os, signal, sys
import rti_rig.cli.session as s
real = s._execute
def execute(*args, **kwargs):
    os.kill(os.getpid(), getattr(signal, os.environ["HAND_OVER_SIGNAL"]))
    return real(*args, **kwargs)
s._execute = execute
from rti_rig.cli import app
app(sys.argv[1:])
"""


def run_terminated(*argv: str, sig: str = "SIGTERM") -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "200", "HAND_OVER_SIGNAL": sig}
    return subprocess.run(
        [sys.executable, "-c", STOP_AT_HAND_OVER, *argv],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


def said(text: str) -> str:
    return " ".join(text.split())


@pytest.mark.parametrize(
    ("sig", "code", "why"), [("SIGTERM", 143, "SIGTERM"), ("SIGINT", 130, "Ctrl-C")]
)
def test_a_stop_as_a_new_session_hands_over_stops_it_with_a_word(
    tmp_path: Path, sig: str, code: int, why: str
) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    proc = run_terminated("run", str(cfg), "--out", str(out), "--lights", "8", sig=sig)
    assert proc.returncode == code, (proc.returncode, proc.stderr)
    stopped = f"Stopped ({why}) before the first image: nothing was captured"
    assert stopped in said(proc.stderr), proc.stderr
    assert not out.exists() or not any(out.glob("image_*"))


def test_a_sigterm_as_a_resume_hands_over_says_how_to_go_on(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    from rti_rig.testing.kill_hooks import popen_session

    killed = popen_session("before_journal", 3, cfg, out, 8)  # image_004 left unjournaled
    _, stderr = killed.communicate(timeout=120)
    assert killed.returncode == -signal.SIGKILL, stderr.decode()
    proc = run_terminated("run", "--resume", str(out))
    assert proc.returncode == 143, (proc.returncode, proc.stderr)
    text = said(proc.stdout + proc.stderr)
    assert "moved to recovered/" in text, text
    assert "Stopped (SIGTERM) before the session went on: no new image was captured; " in text
    assert f"rti-rig run --resume {out}" in text, text
    r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output  # the folder was left closed and resumable
    assert len(list(out.glob("image_*.jpg"))) == 8
