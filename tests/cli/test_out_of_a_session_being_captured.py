"""`rti-rig run … --out S` while another process captures into S does not call S interrupted.

Found by a front-door audit: two runs started at once with the same `--out` (two terminals, or a
script run twice): the second was told "S is not empty … or continue the interrupted session in
it with rti-rig run --resume S" — S was not interrupted but being captured, and that resume is
refused ("in use by another rti-rig process"). The running capture is stood in for by a process
holding the session's lock, as `rti-rig run` holds it (an flock on the folder), and by the
manifest a running capture has written (``runner.state = "running"``).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from conftest import CONFIGS, line_within, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()

HOLD = (
    "import fcntl, os, sys\n"
    "fd = os.open(sys.argv[1], os.O_RDONLY)\n"
    "fcntl.flock(fd, fcntl.LOCK_EX)\n"
    "print('held', flush=True)\n"
    "sys.stdin.read()\n"
)


def _run_while_captured(tmp_path: Path, out: str) -> str:
    """``rti-rig run --out S/out`` while another process holds S as a running capture does."""
    config = str(CONFIGS / "virtual_arm.toml")
    session = tmp_path / "s"
    r = runner.invoke(app, ["run", config, "--out", str(session), "--lights", "3", "--no-verdict"])
    assert r.exit_code == 0, r.output
    manifest = session / "manifest.json"
    data = json.loads(manifest.read_text())
    data["runner"] = {"state": "running", "finish_reason": None}  # as a capture under way has it
    manifest.write_text(json.dumps(data))
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(session)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert line_within(holder, 120, "the lock holder's 'held'").strip() == "held"
        r = runner.invoke(app, ["run", config, "--out", str(session / out), "--lights", "3"])
    finally:
        assert holder.stdin is not None
        holder.stdin.close()
        holder.wait(timeout=60)
    text = said(r)
    assert r.exit_code == 2, text
    return text


def test_a_session_being_captured_is_said_to_be_so(tmp_path: Path) -> None:
    text = _run_while_captured(tmp_path, ".")
    assert "another rti-rig process is capturing a session in it right now" in text, text
    assert "interrupted" not in text and "--resume" not in text


def test_a_folder_inside_a_session_being_captured_is_said_to_be_so(tmp_path: Path) -> None:
    # --out S/sub had been told S is "an interrupted session (continue it with rti-rig run
    # --resume S)", a resume the running capture refuses
    text = _run_while_captured(tmp_path, "sub")
    assert "another rti-rig process is capturing into right now" in text, text
    assert "interrupted" not in text and "--resume" not in text
