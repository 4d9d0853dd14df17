"""A run stopped once every image is in (a SIGTERM held while the last image was committed,
or during an arm's final park) says the session is complete and that fit is next.

Why: it said "Continue with: rti-rig run --resume S" of a complete session, which has nothing
left to resume. A stop with images missing still says the resume.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO

#: ``rti-rig run`` in a process of its own that sends itself SIGTERM as image ``AT`` (0-based)
#: is committed: the commit holds the signal, which stops the run right after it
SCRIPT = """
import os, signal, sys
from rti_rig.runtime.session import SessionFolder
AT = int(sys.argv.pop(1))
real = SessionFolder.write_step
def write_step(self, i, *a, **k):
    if i == AT:
        os.kill(os.getpid(), signal.SIGTERM)
    return real(self, i, *a, **k)
SessionFolder.write_step = write_step
from rti_rig.cli import app
app(sys.argv[1:], prog_name="rti-rig")
"""


def _run_sigterm_at(tmp_path: Path, at: int) -> tuple[int, str, Path]:
    out = tmp_path / "s"
    args = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "6"]
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT, str(at), *args, "--no-verdict"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"},
    )
    return proc.returncode, " ".join((proc.stdout + proc.stderr).split()), out


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_sigterm_as_the_last_image_is_committed_says_complete_and_fit(tmp_path: Path) -> None:
    code, said, out = _run_sigterm_at(tmp_path, 5)
    assert code == 143, said
    assert "Emergency stop (SIGTERM)" in said and "Traceback" not in said, said
    assert "--resume" not in said, said
    assert f"6 image(s) kept in {out}, listed in lights.lp: the session is complete" in said
    assert f"Next: rti-rig fit {out} --out FOLDER" in said, said
    assert len((out / "lights.lp").read_text().splitlines()) == 7  # its count and 6 lights


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_sigterm_with_images_missing_still_says_the_resume(tmp_path: Path) -> None:
    code, said, out = _run_sigterm_at(tmp_path, 2)
    assert code == 143, said
    kept = f"3 image(s) kept in {out}, listed in lights.lp. Continue with: rti-rig run --resume"
    assert kept in said, said
    assert "session is complete" not in said, said
