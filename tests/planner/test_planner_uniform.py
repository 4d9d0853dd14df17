"""Homogeneous layouts: no repeated LEDs, floors respected, clear errors at the extremes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction, fibonacci_cap
from rti_rig.core.lp_format import LpEntry
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.from_lp import schedule_from_lp
from rti_rig.planner.uniform import plan_uniform, select_uniform_leds

DOME = DomeGeometry(fibonacci_cap(72, 5.0, 88.0), tuple(f"l{i:02d}.jpg" for i in range(72)))
ARM = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)


@given(st.integers(1, 72), st.sampled_from([0.0, 10.0, 20.0]))
@settings(max_examples=40, deadline=None)
def test_dome_selection_unique_and_above_floor(n: int, floor: float) -> None:
    _, el = az_el_from_direction(DOME.directions)
    available = int(np.sum(el >= floor))
    if n > available:
        with pytest.raises(ScheduleError, match=f"only {available} LEDs"):
            select_uniform_leds(DOME, n, floor)
        return
    leds = select_uniform_leds(DOME, n, floor)
    assert len(leds) == n == len(set(leds.tolist()))
    assert np.all(el[leds] >= floor - 1e-9)


def test_uniform_spreads_better_than_first_n() -> None:
    """The chosen LEDs cover the hemisphere: every LED is near a chosen one."""
    leds = select_uniform_leds(DOME, 12)
    chosen = DOME.directions[leds]
    worst_gap = angle_between_deg(DOME.directions[:, None], chosen[None]).min(axis=1).max()
    naive = DOME.directions[:12]
    naive_gap = angle_between_deg(DOME.directions[:, None], naive[None]).min(axis=1).max()
    assert worst_gap < 0.6 * naive_gap
    assert worst_gap < 35.0


def test_azimuth_offset_turns_the_layout() -> None:
    """On a dome symmetric under a 90° turn, a 90° offset gives the turned LED set."""
    az_el = [(a, 20.0) for a in range(0, 360, 15)] + [(a, 50.0) for a in range(0, 360, 30)]
    az0, el0 = np.array(az_el, dtype=float).T
    dirs = np.stack(
        [
            np.cos(np.radians(el0)) * np.cos(np.radians(az0)),
            np.cos(np.radians(el0)) * np.sin(np.radians(az0)),
            np.sin(np.radians(el0)),
        ],
        axis=1,
    )
    dome = DomeGeometry(dirs, tuple(str(i) for i in range(len(dirs))))
    base = select_uniform_leds(dome, 7)
    turned = select_uniform_leds(dome, 7, azimuth_offset_deg=90.0)
    want = sorted(zip(np.round((az0[base] + 90.0) % 360.0, 6), el0[base], strict=True))
    got = sorted(zip(np.round(az0[turned] % 360.0, 6), el0[turned], strict=True))
    assert got == want
    assert set(base.tolist()) != set(turned.tolist())


@pytest.mark.parametrize("n", [1, 2, 3, 25])
def test_arm_plans_are_reachable(n: int) -> None:
    sched = plan_uniform(ARM, n, 15.0)
    assert len(sched) == n
    for s in sched.steps:
        assert ARM.unreachable_reason(np.array(s.direction)) is None
        assert s.elevation_deg >= 15.0 - 1e-9


def test_bad_requests() -> None:
    with pytest.raises(ScheduleError, match="at least 1"):
        plan_uniform(DOME, 0)
    with pytest.raises(ScheduleError, match="no reachable band"):
        plan_uniform(ARM, 5, 85.0)


def test_plan_snaps_to_leds_and_refuses_repeats() -> None:
    e = [
        LpEntry("a_1.jpg", tuple(DOME.directions[3])),
        LpEntry("a_2.jpg", tuple(DOME.directions[7])),
    ]
    sched = schedule_from_lp(e, DOME, "p.lp")
    assert [s.led for s in sched.steps] == [3, 7]
    with pytest.raises(ScheduleError, match="already used by light 1"):
        schedule_from_lp([e[0], LpEntry("a_3.jpg", e[0].direction)], DOME, "p.lp")
    with pytest.raises(ScheduleError, match="keep-out"):
        schedule_from_lp([LpEntry("z_1.jpg", (0, 0, 1))], ARM, "p.lp")
