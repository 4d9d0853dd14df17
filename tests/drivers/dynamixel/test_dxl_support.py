"""The Dynamixel test helpers (tests/dxl_support.py) make a valid, overridable arm."""

from __future__ import annotations

from dxl_support import arm_settings


def test_default_test_arm_is_valid_and_overridable() -> None:
    s = arm_settings(azimuth=dict(servo_id=7))
    assert s.servo_ids == (7, 2)
    assert s.azimuth.tick_limits == (114, 3982)  # 2048 -+ 170 deg / 0.0879 deg, rounded in
