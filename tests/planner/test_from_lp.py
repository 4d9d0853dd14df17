"""A plan `.lp` run on a rig: `rti-rig run RIG --plan PLAN.lp`, through the front door."""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
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
    assert "the plan was made for another rig — replan for this arm: " in said, said
    assert not (tmp_path / "s").exists()


def test_the_replan_commands_paste_and_run_on_this_arm(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The refusal's commands are this rig's, pasteable as printed: it had said "replan with
    --rig for this arm", leaving the user to spell out the command, its config and .lp."""
    monkeypatch.chdir(tmp_path)
    cfg = tmp_path / "my arm.toml"  # a name that must be quoted to paste
    cfg.write_text((REPO / "rig_configs" / "virtual_arm.toml").read_text())
    plan = tmp_path / "plan.lp"  # taken: the hint's plan is another file
    plan.write_text(
        "3\nimage_001.jpg 0.999190 0.000000 0.040247\nimage_002.jpg 0 0.6 0.8\n"
        "image_003.jpg -0.6 0 0.8\n"
    )
    r = runner.invoke(app, ["run", cfg.name, "--plan", "plan.lp", "--out", "s"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    replan = said.split("replan for this arm: ", 1)[1]
    plan_cmd, run_cmd = replan.split(" (add its preview, if the plan had one), then ")
    assert plan_cmd == "rti-rig plan --rig 'my arm.toml' --lights 3 --out plan-2.lp", said
    assert run_cmd == "rti-rig run 'my arm.toml' --plan plan-2.lp --out s", said
    r = runner.invoke(app, shlex.split(plan_cmd)[1:])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, [*shlex.split(run_cmd)[1:], "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "s" / "lights.lp").read_text().split()[0] == "3"
