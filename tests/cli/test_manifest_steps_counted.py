"""``runner.steps_planned`` and ``runner.steps_done`` of manifest.json, which guide §11 tells
scripts to read, are there from a run's start, not only once its end is recorded.

Before: both were written only by a run's recorded end, so a run killed outright (kill -9, a
power cut) left a manifest with neither, as did every run still under way, and a script that
read them found nothing. ``steps_done`` during a run is the count when that run began (the
manifest is not rewritten per image): a lower bound that lights.lp's first line, rewritten as
each image is committed, brings up to date.
"""

from __future__ import annotations

import json
import signal
from pathlib import Path

from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.kill_hooks import popen_argv, popen_session

LIGHTS = 8


def _runner(out: Path) -> dict:
    return json.loads((out / "manifest.json").read_text())["runner"]


def _lp_count(out: Path) -> int:
    return int((out / "lights.lp").read_text().splitlines()[0])


def test_a_killed_run_and_its_killed_resume_leave_both_counts(tmp_path: Path) -> None:
    out = tmp_path / "s"
    proc = popen_session("before_light", 3, CONFIGS / "simulated_dome.toml", out, LIGHTS)
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    runner = _runner(out)
    assert runner["state"] == "running" and runner["finish_reason"] is None, runner
    assert runner["steps_planned"] == LIGHTS, runner
    assert runner["steps_done"] == 0, runner  # the count when the run began
    assert _lp_count(out) == 3  # the live count: image_000…image_002 committed

    # a resume killed in its turn records what was done when it began
    proc = popen_argv("before_light", 2, ["run", "--resume", str(out), "--no-verdict"])
    _, stderr = proc.communicate(timeout=300)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    runner = _runner(out)
    assert runner["steps_planned"] == LIGHTS and runner["steps_done"] == 3, runner
    assert _lp_count(out) == 5

    r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    runner = _runner(out)
    assert runner["finish_reason"] == "completed", runner
    assert runner["steps_done"] == runner["steps_planned"] == LIGHTS == _lp_count(out), runner
