"""Shared helpers for the Dynamixel arm tests (imported by them from tests/)."""

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
