"""Shared helpers for the Dynamixel arm tests (imported by the others), and their tests."""

from __future__ import annotations

import pytest
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


@pytest.fixture
def wide_sdk_timeouts(monkeypatch):
    """Widen the SDK's reply timeout from ~34 ms to ~200 ms for pty tests: the machine is
    shared and the emulator thread competes with the SDK's busy-wait for the GIL. Only a
    missing reply ever waits this long, and the pty tests expect none."""
    import dynamixel_sdk.port_handler as port_handler

    monkeypatch.setattr(port_handler, "LATENCY_TIMER", 100)


def test_default_test_arm_is_valid_and_overridable() -> None:
    s = arm_settings(azimuth=dict(servo_id=7))
    assert s.servo_ids == (7, 2)
    assert s.azimuth.tick_limits == (114, 3982)  # 2048 -+ 170 deg / 0.0879 deg, rounded in


def test_wide_sdk_timeouts_fixture(wide_sdk_timeouts) -> None:
    import dynamixel_sdk.port_handler as port_handler

    assert port_handler.LATENCY_TIMER == 100
