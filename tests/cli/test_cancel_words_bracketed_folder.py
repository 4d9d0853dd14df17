"""A run cancelled by Ctrl-C in a folder whose name holds square brackets (``scan [v2]``, a
common way to mark a version) says the resume of that very folder.

Why: the cancelled run's last line went through rich's markup with the resume command
unescaped, so ``[v2]`` was taken for a style tag and dropped: it said ``Continue with: rti-rig
run --resume '…/scan '``, which pasted resumed another folder or none (a ``[/x]`` in the name
would have ended the run in a MarkupError traceback).
"""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO
from sigterm_support import signal_at_commit

#: ``rti-rig run`` that sends itself a Ctrl-C (SIGINT) as image ``AT`` (0-based) is committed:
#: the commit holds it, and the run stops after that image, cancelled
SCRIPT = signal_at_commit("SIGINT")


@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_a_cancelled_run_in_a_bracketed_folder_names_that_folder_to_resume(
    tmp_path: Path,
) -> None:
    out = tmp_path / "scan [v2]"
    args = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "4"]
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT, "1", *args, "--no-verdict"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"},
    )
    said = " ".join((proc.stdout + proc.stderr).split())
    assert proc.returncode == 130, said
    assert "Session cancelled" in said and "Traceback" not in said, said
    assert "Continue with: rti-rig run --resume " in said, said
    rest = said.split("Continue with: rti-rig run --resume ", 1)[1]
    words = shlex.shlex(rest, posix=True, punctuation_chars=False)
    words.whitespace_split = True
    assert Path(next(iter(words))) == out, said
