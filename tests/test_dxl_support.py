"""Shared helpers for the Dynamixel arm tests (imported by the others), and their tests."""

from __future__ import annotations

from rti_rig.drivers.dynamixel.settings import ArmSettings


def arm_settings(**overrides) -> ArmSettings:
    """A plausible XL430 arm: azimuth +-170 deg, elevation 0..90, 15 deg keep-out cone."""
    base = dict(
        port="emulated",
        azimuth=dict(
            servo_id=1, model_number=1060, zero_offset_ticks=2048, min_deg=-170.0, max_deg=170.0
        ),
        elevation=dict(
            servo_id=2, model_number=1060, zero_offset_ticks=1024, min_deg=0.0, max_deg=90.0
        ),
        keep_out_half_angle_deg=15.0,
        move_timeout_s=20.0,
    )
    for key, value in overrides.items():
        if key in ("azimuth", "elevation"):
            base[key] = {**base[key], **value}
        else:
            base[key] = value
    return ArmSettings(**base)


def test_default_test_arm_is_valid_and_overridable() -> None:
    s = arm_settings(azimuth=dict(servo_id=7))
    assert s.servo_ids == (7, 2)
    assert s.azimuth.tick_limits == (114, 3982)  # 2048 -+ 170 deg / 0.0879 deg, rounded in
