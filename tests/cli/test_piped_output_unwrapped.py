"""A command whose output is piped (a script's ``| grep``, ``> log``) prints each message on
one line, however long.

Rich wraps at 80 columns where there is no terminal, so a piped ``fit`` broke its ``QA verdict:
reshoot: image_003 (...)`` line over six lines, mid-advice (``rti-rig run --resume S`` /
``--reshoot-lost``), and ``run``'s ``Rig ... → OUT`` line split a long --out path: a script
reading the verdict line got its first 80 characters. Through ``python -m rti_rig``, the
console entry a shell script uses, with stdout and stderr pipes.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from conftest import CONFIGS, REPO


def _rti_rig(*args: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    env.pop("COLUMNS", None)  # rich's width without a terminal: 80, unless COLUMNS says
    return subprocess.run(
        [sys.executable, "-m", "rti_rig", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )


def test_piped_run_and_fit_say_each_message_on_one_line(tmp_path: Path) -> None:
    session = tmp_path / ("inspected_part_" + "x" * 80) / "s"
    r = _rti_rig(
        "run", str(CONFIGS / "simulated_dome.toml"), "--out", str(session), "--lights", "6"
    )
    assert r.returncode == 0, r.stdout + r.stderr
    lines = r.stdout.splitlines()
    # the announcement names the --out folder whole, on the line that starts it
    assert any(line.startswith("Rig ") and line.endswith(f"→ {session}") for line in lines), (
        r.stdout
    )

    # a wrong image: image_001's files saved under image_003's name
    shutil.copy(session / "image_001.jpg", session / "image_003.jpg")
    shutil.copy(session / "linear" / "image_001.tif", session / "linear" / "image_003.tif")
    fitted = tmp_path / "fit"
    r = _rti_rig("fit", str(session), "--out", str(fitted), "--no-ptm", "--no-hsh")
    assert r.returncode == 0, r.stdout + r.stderr
    verdict = [line for line in r.stdout.splitlines() if line.startswith("QA verdict: ")]
    assert len(verdict) == 1, r.stdout
    # the whole verdict, its advice with the session's path and the option to give, on one line
    assert verdict[0].startswith("QA verdict: reshoot: image_003 ("), verdict[0]
    assert f"rti-rig run --resume {session} --reshoot-lost" in verdict[0], r.stdout
    assert verdict[0].endswith(")"), r.stdout
    # the console's words are the same as those of qa.json, which a script can read instead
    qa = json.loads((fitted / "qa.json").read_text())
    assert verdict[0] == f"QA verdict: {qa['verdict']}"
    assert qa["good"] is False and qa["reshoot"] == ["image_003"]
