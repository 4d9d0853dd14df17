"""docs/planning.md says how long the shipped simulated arm's dry run of a uniform plan takes on
the real rig ("17 s for 6 lights, 29 s for 12 …"), a figure a reader uses to choose a light
count. No test read it: walking the page found 30 s for 12 lights where the run said 29.3 s
(the arm's move order had changed since). The 12-light plan is checked, through the CLI."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO
from typer.testing import CliRunner

from rti_rig.cli import app

PLANNING = REPO / "docs" / "planning.md"
ARM = CONFIGS / "simulated_arm.toml"


def _said_seconds(lights: int) -> float:
    """The seconds planning.md gives for a uniform plan of ``lights`` on the simulated arm."""
    text = " ".join(PLANNING.read_text(encoding="utf-8").split())
    found = re.search(r"\(uniform: no preview\) reports (\d+) s for 6 lights, (\d+) s for 12", text)
    assert found, "planning.md's arm dry-run times are gone"
    return float(found.group({6: 1, 12: 2}[lights]))


@pytest.mark.slow
@pytest.mark.e2e
def test_planning_md_gives_the_simulated_arms_time_for_a_12_light_uniform_plan(
    tmp_path: Path,
) -> None:
    runner = CliRunner()
    plan, out = tmp_path / "plan.lp", tmp_path / "s"
    r = runner.invoke(app, ["plan", "--rig", str(ARM), "--lights", "12", "--out", str(plan)])
    assert r.exit_code == 0, r.output
    assert "method uniform" in r.output, r.output  # no preview: the page's "uniform"
    r = runner.invoke(
        app, ["run", str(ARM), "--plan", str(plan), "--out", str(out), "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    rig_s = json.loads((out / "manifest.json").read_text(encoding="utf-8"))["timing"]["rig_time_s"]
    # whole seconds on the page; the arm's clock is simulated, so the figure is the same each run
    assert abs(_said_seconds(12) - rig_s) <= 0.5, (_said_seconds(12), rig_s)
