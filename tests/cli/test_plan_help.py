"""What `rti-rig plan --help` says of an arm's order matches what the planner does.

Why: the help said every arm's lights were "ordered for the least move time", but only a
config with servo settings ([arm.dynamixel], e.g. simulated_arm.toml) got the move-time order;
virtual_arm.toml's plan was ordered nearest neighbour first, which on that arm's non-wrapping
azimuth took 39.1 s of session time for 12 lights the move-time order runs in 34.9 s.
Now every arm is ordered by its move time (rti_rig.app.compose.arm_order_for): the servos' or
the simulated arm's (tests/cli/test_plan_arm_order.py), and the help says which.
"""

from __future__ import annotations

from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_plan_help_says_which_arms_are_ordered_for_move_time() -> None:
    r = runner.invoke(app, ["plan", "--help"], terminal_width=200)
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.replace("│", " ").split())
    assert "ordered for the least move time: of its servos when the config has" in text
    assert "[arm.dynamixel], of the simulated arm's [arm] speed and limits otherwise" in text
    assert "nearest neighbour" not in text


def test_plan_help_says_where_a_raw_previews_light_comes_from() -> None:
    # a session's RAW original (raw/image_007.dng) takes its light from the session's record
    # (rti_rig.app.preview_source); the help named only --preview-light and a --rig .lp
    r = runner.invoke(app, ["plan", "--help"], terminal_width=200)
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.replace("│", " ").split())
    assert (
        "its light taken from --preview-light, the rti-rig session it was captured in, or" in text
    )
