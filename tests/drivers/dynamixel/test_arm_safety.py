"""Property tests: no goal outside the joint limits or into the keep-out cone ever reaches the
bus, over random arm configs and random schedules (checked on the emulator's goal log, with
the limits recomputed here from the config rather than taken from the driver)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dxl_support import arm_settings
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rti_rig.core.clock import VirtualClock
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.faults import UnreachableError
from rti_rig.drivers.dynamixel.kinematics import ArmKinematics
from rti_rig.drivers.dynamixel.settings import ArmSettings
from rti_rig.simulator.dynamixel_emulator import InProcessPort, emulator_for_arm

DPT = 360.0 / 4096.0


@st.composite
def arm_configs(draw) -> ArmSettings:
    extended = draw(st.booleans())
    az_dir = draw(st.sampled_from([1, -1]))
    el_dir = draw(st.sampled_from([1, -1]))
    gear = draw(st.sampled_from([1.0, 0.5, 1.5]))
    az_span = draw(st.floats(60.0, 700.0 if extended else 330.0))
    if not extended:
        az_span = min(az_span, 3900 * DPT / gear)
    az_min = draw(st.floats(-350.0, 0.0))
    az_max = az_min + az_span
    if extended:
        az_zero = draw(st.integers(-20000, 20000))
    else:
        span_ticks = az_span * gear / DPT
        low = draw(st.integers(10, int(4085 - span_ticks)))
        az_zero = math.ceil(low - min(az_dir * gear * az_min, az_dir * gear * az_max) / DPT)
    el_min = draw(st.floats(-10.0, 20.0))
    el_max = draw(st.floats(el_min + 30.0, 90.0))
    keep_out = min(draw(st.floats(0.0, 60.0)), 89.0 - el_min - 5.0)
    park_el = draw(st.floats(el_min + 0.5, min(el_max, 90.0 - keep_out) - 0.5))
    # within both models' factory Velocity Limit (XM430-W350 200 x 0.229 = 45.8 rpm, e-manual):
    # 50 rpm had passed only because the emulator gave every model the XL430's table
    profile = dict(profile_velocity_rpm=40.0, profile_acceleration_rev_min2=5000.0)
    return ArmSettings(
        port="emulated",
        azimuth=dict(
            servo_id=1,
            model_number=1060,
            zero_offset_ticks=az_zero,
            direction=az_dir,
            gear_ratio=gear,
            min_deg=az_min,
            max_deg=az_max,
            operating_mode="extended_position" if extended else "position",
            **profile,
        ),
        elevation=dict(
            servo_id=2,
            model_number=1020,
            zero_offset_ticks=2048,
            direction=el_dir,
            min_deg=el_min,
            max_deg=el_max,
            **profile,
        ),
        keep_out_half_angle_deg=keep_out,
        park_azimuth_deg=az_min + az_span / 2,
        park_elevation_deg=park_el,
        poll_interval_s=0.05,
    )


def independent_check(
    cfg: ArmSettings, servo_id: int, ticks: int, slack_deg: float = 1e-6
) -> str | None:
    """Limits and cone from first principles (not via the driver's kinematics), each widened
    by ``slack_deg`` (negative: narrowed) for float noise."""
    joint = cfg.azimuth if servo_id == cfg.azimuth.servo_id else cfg.elevation
    deg = (ticks - joint.zero_offset_ticks) / (joint.direction * joint.gear_ratio) * DPT
    if not joint.min_deg - slack_deg <= deg <= joint.max_deg + slack_deg:
        return f"servo {servo_id} at {deg} deg outside {joint.min_deg}..{joint.max_deg}"
    if joint is cfg.elevation and deg > 90.0 - cfg.keep_out_half_angle_deg + slack_deg:
        return f"elevation {deg} deg inside the keep-out cone"
    return None


def schedules(cfg: ArmSettings):
    """Directions mostly around the reachable box, spilling past its edges (limits, cone,
    below the horizon), plus arbitrary directions."""
    el_top = 90.0 - cfg.keep_out_half_angle_deg
    az_lo, az_hi = cfg.azimuth.min_deg, cfg.azimuth.max_deg
    el_lo = cfg.elevation.min_deg
    near = st.tuples(st.floats(-0.1, 1.1), st.floats(-0.15, 1.15)).map(
        lambda f: tuple(
            direction_from_az_el(
                az_lo + f[0] * (az_hi - az_lo), min(89.9, el_lo + f[1] * (el_top - el_lo))
            )
        )
    )
    cone_edge = st.tuples(st.floats(0.0, 1.0), st.floats(-2.0, 4.0)).map(
        lambda f: tuple(
            direction_from_az_el(az_lo + f[0] * (az_hi - az_lo), min(89.9, el_top + f[1]))
        )
    )
    anywhere = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-0.3, 1)).filter(
        lambda v: math.hypot(*v) > 0.1
    )
    return st.lists(st.one_of(near, near, cone_edge, anywhere), min_size=1, max_size=8)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cfg=arm_configs(), data=st.data())
@pytest.mark.slow
def test_no_unsafe_goal_ever_reaches_the_bus(cfg: ArmSettings, data) -> None:
    schedule = data.draw(schedules(cfg))
    clock = VirtualClock()
    emu = emulator_for_arm(cfg, clock)
    arm = DynamixelArm(cfg, InProcessPort(emu), clock)
    arm.connect()
    moved = refused = 0
    for v in schedule:
        d = np.asarray(v) / np.linalg.norm(v)
        reason = arm.unreachable_reason(d)
        try:
            arm.move_to(d)
            moved += 1
        except UnreachableError:
            refused += 1
            assert reason is not None
    arm.close()
    assert moved + refused == len(schedule)
    assert emu.goal_log, "close() parks, so at least one goal was sent"
    for servo_id, ticks in emu.goal_log:
        assert independent_check(cfg, servo_id, ticks) is None, (servo_id, ticks)


@settings(max_examples=200, deadline=None)
@given(cfg=arm_configs(), az=st.integers(-40000, 40000), el_offset=st.integers(-300, 300))
def test_gate_refuses_any_unsafe_tick_pair(cfg: ArmSettings, az: int, el_offset: int) -> None:
    """Elevation goals are drawn around the cone's edge, where mistakes would hide."""
    j = cfg.elevation
    edge = j.zero_offset_ticks + j.direction * (90.0 - cfg.keep_out_half_angle_deg) / DPT
    el = round(edge) + el_offset
    gate_ok = ArmKinematics(cfg).ticks_reason(az, el) is None

    def independent_ok(slack_deg: float) -> bool:
        return (
            independent_check(cfg, 1, az, slack_deg) is None
            and independent_check(cfg, 2, el, slack_deg) is None
        )

    # safe: nothing the gate passes is outside a limit (beyond float noise); usable: all that
    # is inside every limit by more than that noise passes. A tick within 1e-6 deg of a limit
    # may go either way (hypothesis found a limit of 59.99999988 deg, 2e-6 ticks inside tick
    # 10: the gate rounds it inwards, the oracle's slack had let it pass, and equality failed)
    if gate_ok:
        assert independent_ok(1e-6)
    if independent_ok(-1e-6):
        assert gate_ok


def test_direction_on_a_degree_limit_is_reachable_from_either_side() -> None:
    """Regression (found by the property test): a pose on a degree limit lies up to one tick
    outside the inward-rounded tick limits; it must be clamped, not refused."""
    cfg = ArmSettings(
        port="emulated",
        azimuth=dict(
            servo_id=1,
            model_number=1060,
            zero_offset_ticks=0,
            min_deg=-1.0,
            max_deg=359.0,
            operating_mode="extended_position",
        ),
        elevation=dict(
            servo_id=2, model_number=1020, zero_offset_ticks=2048, min_deg=0.0, max_deg=30.0
        ),
        keep_out_half_angle_deg=0.0,
        park_azimuth_deg=179.0,
        park_elevation_deg=1.0,
    )
    kin = ArmKinematics(cfg)
    d = direction_from_az_el(-1.0, 0.0)
    for ref in (0.0, 179.0, 179.03, 358.0):
        pose, reason = kin.solve(d, ref)
        assert reason is None and pose is not None
        assert kin.ticks_reason(*kin.ticks_of_pose(*pose)) is None


@pytest.mark.parametrize("half_angle", [15.0, 14.95, 14.99])
def test_a_light_on_the_keep_out_edge_as_an_lp_writes_it_is_reachable(half_angle: float) -> None:
    """A light planned exactly on the cone's edge, read back from an `.lp`'s six decimals, lies
    up to ~1e-4° either side of it: it was refused ("inside the keep-out cone"), and where the
    edge's tick rounded up into the cone the gate refused it too. It is now on the edge: its
    ticks are the nearest outside the cone, which the exact gate passes; a light 0.01° inside
    the cone is still refused."""
    kin = ArmKinematics(arm_settings(keep_out_half_angle_deg=half_angle, park_elevation_deg=10.0))
    edge = 90.0 - half_angle
    for az in (0.0, 37.0, -120.0):
        on_edge = np.round(direction_from_az_el(az, edge), 6)  # as an .lp stores it
        pose, reason = kin.solve(on_edge)
        assert reason is None and pose is not None, reason
        el_ticks = kin.ticks_of_pose(*pose)[1]
        assert kin.ticks_reason(*kin.ticks_of_pose(*pose)) is None
        assert (el_ticks - 1024) * DPT <= edge + 1e-9
        assert kin.solve(direction_from_az_el(az, edge + 0.01))[1] is not None
