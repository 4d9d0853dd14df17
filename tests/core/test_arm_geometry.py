"""An arm's homogeneous layout: the equal-area layout of the reachable band, its azimuths
mapped linearly onto the base joint's range (5b7a7d03: they had been clamped onto its limits,
bunching the lights of the unreachable azimuths at them)."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.geometry import az_el_from_direction, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry

ARMS = [
    ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0),
    ArmGeometry(0.0, 90.0, 15.0, 0.0, 10.0, -170.0, 170.0),
    ArmGeometry(20.0, 70.0, 20.0, 0.0, 30.0, -90.0, 120.0),
]


def _signed(az: np.ndarray) -> np.ndarray:
    return np.where(az > 180.0, az - 360.0, az)


@pytest.mark.parametrize("arm", ARMS)
@pytest.mark.parametrize("n", [1, 7, 36, 100, 331])
@pytest.mark.parametrize("floor", [0.0, 25.0])
def test_homogeneous_maps_each_fibonacci_azimuth_onto_the_arm_range(arm, n, floor) -> None:
    """Each direction keeps its equal-area elevation; its azimuth (-180..180) is mapped onto
    the arm's range in the same order (an arm turning all the way round keeps it as it is)."""
    lo, hi = arm.elevation_band(floor)
    az_fib, el_fib = az_el_from_direction(fibonacci_cap(n, lo, hi))
    got = arm.homogeneous(n, floor)
    assert got.shape == (n, 3)
    np.testing.assert_array_equal(got, arm.homogeneous(n, floor))  # the planner's index
    az, el = az_el_from_direction(got)
    np.testing.assert_allclose(el, el_fib, atol=1e-9)
    span = arm.max_azimuth_deg - arm.min_azimuth_deg
    if span >= 360.0:
        want = _signed(az_fib)
    else:
        want = arm.min_azimuth_deg + (_signed(az_fib) + 180.0) * span / 360.0
    flat = np.cos(np.radians(el)) > 1e-9  # a direction straight up has no azimuth to map
    np.testing.assert_allclose(_signed(az)[flat], want[flat], atol=1e-7)
    az = _signed(az)
    assert np.all(az >= arm.min_azimuth_deg - 1e-9) and np.all(az <= arm.max_azimuth_deg + 1e-9)


def test_homogeneous_does_not_bunch_lights_at_a_limit() -> None:
    """On a ±170° arm no two lights of an even layout share the limit's azimuth (clamping had
    put every light of the 20° it cannot reach at exactly ±170°)."""
    arm = ARMS[1]
    az, _ = az_el_from_direction(arm.homogeneous(24))
    at_limit = np.isclose(np.abs(_signed(az)), 170.0, atol=1e-6)
    assert at_limit.sum() <= 1, _signed(az)
