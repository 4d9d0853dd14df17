"""A plan `.lp` run on a rig: `rti-rig run RIG --plan PLAN.lp`, through the front door."""

from __future__ import annotations

from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def test_an_arm_plan_out_of_reach_says_to_replan_for_this_arm(tmp_path: Path) -> None:
    """A plan made for an arm that reaches lower (simulated_arm, 0°) run on one that does not
    (virtual_arm, 5°): the refusal had said only why ("elevation 2.31° is below the arm's
    minimum 5°"), where a dome's says to replan with --rig."""
    plan = tmp_path / "plan.lp"
    plan.write_text("2\nimage_001.jpg 0.999190 0.000000 0.040247\nimage_002.jpg 0 0.6 0.8\n")
    cfg = REPO / "rig_configs" / "virtual_arm.toml"
    r = runner.invoke(app, ["run", str(cfg), "--plan", str(plan), "--out", str(tmp_path / "s")])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "light 1 (image_001.jpg): elevation 2.31° is below the arm's minimum 5°" in said
    assert "replan with --rig for this arm" in said and not (tmp_path / "s").exists()
