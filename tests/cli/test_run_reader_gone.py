"""A run whose output's reader goes away (``rti-rig run ... | head -1``, a script that read the
line it wanted) finishes its session and exits by the session, not by the pipe.

click turned the first write to the closed pipe into exit 1 without a word: a session that had
completed, all its images and manifest written, exited 1, which says "the rig was not made
safe, or a fault rti-rig did not name", and its summary and verdict were cut off. Through
``python -m rti_rig``, the console entry a shell pipeline runs.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from conftest import CONFIGS, REPO, ended_on_exit, line_within


def test_a_run_piped_into_head_completes_and_exits_0(tmp_path: Path) -> None:
    out = tmp_path / "s"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    with open(tmp_path / "stderr.txt", "w") as stderr:
        run = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "rti_rig",
                "run",
                str(CONFIGS / "simulated_dome.toml"),
                "--out",
                str(out),
                "--lights",
                "6",
            ],
            stdout=subprocess.PIPE,
            stderr=stderr,
            env=env,
            text=True,
        )
        with ended_on_exit(run):
            # the first line is said before the rig opens: the rest is written to a closed pipe
            assert line_within(run, 300, "the run's first line").startswith("Rig ")
            run.stdout.close()  # type: ignore[union-attr]
            code = run.wait(timeout=600)
    said = (tmp_path / "stderr.txt").read_text()
    assert code == 0, said
    assert "Traceback" not in said and "BrokenPipe" not in said and "Exception" not in said, said
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == "completed" and runner["steps_done"] == 6, runner
