"""``rti-rig plan --method adaptive`` is refused, and the refusal says where adaptive is.

An adaptive session is a way to run, not a plan: it chooses each light from the images it
has captured. The refusal had been only "--method 'adaptive' is not known; choose uniform,
kmeans, optimal", leaving a user who read docs/adaptive.md no way on."""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app


def test_plan_method_adaptive_points_to_run_adaptive(tmp_path: Path) -> None:
    out = tmp_path / "plan.lp"
    args = ["plan", "--rig", str(CONFIGS / "simulated_arm.toml"), "--method", "adaptive"]
    r = CliRunner(env={"COLUMNS": "400"}).invoke(app, [*args, "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert "--method 'adaptive' is not known; choose uniform" in text, text
    rig = CONFIGS / "simulated_arm.toml"
    # plan's count and a folder beside the plan that is not there yet (N and DIR had been said)
    assert f"rti-rig run {rig} --adaptive --lights 12 --out {tmp_path / 'planned'})" in text, text
    assert "RIG.toml" not in text, text  # the config at hand is named, not a placeholder
    assert not out.exists()


def test_a_bare_lp_rig_is_offered_the_config_that_lists_it(tmp_path: Path) -> None:
    """A bare .lp given as --rig lists a dome's lights, and is no config to run adaptively:
    the first config beside it whose lp_file it is is named (RIG.toml had been said)."""
    args = ["plan", "--rig", str(CONFIGS / "example_dome_48.lp"), "--method", "adaptive"]
    r = CliRunner(env={"COLUMNS": "400"}).invoke(app, [*args, "--out", str(tmp_path / "p.lp")])
    text = said(r)
    assert r.exit_code == 2, text
    config = CONFIGS / "emulated_dome.toml"
    assert f"rti-rig run {config} --adaptive --lights 12 --out {tmp_path / 'planned'})" in text


def test_another_unknown_method_is_not_sent_to_run_adaptive(tmp_path: Path) -> None:
    args = ["plan", "--rig", str(CONFIGS / "simulated_arm.toml"), "--method", "random"]
    r = CliRunner(env={"COLUMNS": "400"}).invoke(app, [*args, "--out", str(tmp_path / "p.lp")])
    text = said(r)
    assert r.exit_code == 2 and "--method 'random' is not known" in text, text
    assert "--adaptive" not in text, text
