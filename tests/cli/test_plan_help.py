"""What `rti-rig plan --help` says of an arm's order matches what the planner does.

Why: the help said every arm's lights were "ordered for the least move time", but only a
config with servo settings ([arm.dynamixel], e.g. simulated_arm.toml) gets the move-time order
(rti_rig.app.compose.arm_order_for); virtual_arm.toml's plan is ordered nearest neighbour first
(docs/research/planner.md, known limits), which on that arm's non-wrapping azimuth took 39.5 s
of session time for a 12-light plan the move-time order ran in 34.8 s.
"""

from __future__ import annotations

from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_plan_help_says_which_arms_are_ordered_for_move_time() -> None:
    r = runner.invoke(app, ["plan", "--help"], terminal_width=200)
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.replace("│", " ").split())
    assert "ordered for the least move time of its servos when the config has" in text
    assert "[arm.dynamixel], else nearest neighbour first" in text


def test_plan_help_says_where_a_raw_previews_light_comes_from() -> None:
    # a session's RAW original (raw/image_007.dng) takes its light from the session's record
    # (rti_rig.app.preview_source); the help named only --preview-light and a --rig .lp
    r = runner.invoke(app, ["plan", "--help"], terminal_width=200)
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.replace("│", " ").split())
    assert (
        "its light taken from --preview-light, the rti-rig session it was captured in, or" in text
    )
