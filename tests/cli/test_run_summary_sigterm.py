"""A SIGTERM while ``run`` prints the summary of a session that has ended.

The capture's handlers were undone before the summary printed, and a SIGTERM then (a lab
scheduler's ``timeout``) met the default action: exit 143 with no word at all, neither the
images kept nor how to get the QA verdict of a session that had completed. The summary now
prints whole, then the run says the verdict was not computed and which command gives it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from conftest import REPO, SMALL_DOME, write_config

#: runs rti-rig with a SIGTERM sent to itself as the summary's time line is made (a signal at
#: a known point of the summary, not a race against the clock)
HOOK = """
import os, signal, sys
import rti_rig.cli.session as cs
real = cs._time_line
def hooked(*a, **k):
    os.kill(os.getpid(), signal.SIGTERM)
    return real(*a, **k)
cs._time_line = hooked
from rti_rig.cli import app
sys.argv = ["rti-rig", *sys.argv[1:]]
app()
"""


def _run_signalled(tmp_path: Path, *args: str) -> tuple[int, str]:
    """rti-rig ``args`` on a small simulated dome, signalled as its summary prints: the exit
    code and what it said, whitespace folded."""
    hook = tmp_path / "hook.py"
    hook.write_text(HOOK)
    env = {**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"}
    proc = subprocess.run(
        [sys.executable, str(hook), *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    return proc.returncode, " ".join((proc.stdout + proc.stderr).split())


def test_a_sigterm_during_the_summary_keeps_it_and_says_how_to_get_the_verdict(
    tmp_path: Path,
) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    code, said = _run_signalled(tmp_path, "run", str(cfg), "--out", str(out), "--lights", "8")
    assert code == 143, said
    assert "8 image(s) in the session" in said and "Session time on the real rig" in said
    assert "QA verdict was not computed" in said and f"rti-rig fit {out} --out {out}-fit" in said
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed"


def test_a_sigterm_during_the_preview_summary_keeps_the_plan_hint(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "p"
    code, said = _run_signalled(tmp_path, "preview", str(cfg), "--out", str(out))
    assert code == 143, said
    assert f"Plan from it: rti-rig plan {out}" in said and "Stopped (SIGTERM)" in said
