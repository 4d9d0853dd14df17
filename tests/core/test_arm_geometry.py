"""An arm's homogeneous layout: every direction clamped into the base joint's range."""

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


@pytest.mark.parametrize("arm", ARMS)
@pytest.mark.parametrize("n", [1, 7, 36, 100, 331])
@pytest.mark.parametrize("floor", [0.0, 25.0])
def test_homogeneous_is_each_fibonacci_direction_clamped_exactly(arm, n, floor) -> None:
    """The batched layout is, to the bit, :meth:`ArmGeometry.clamp_azimuth` of each direction
    of the equal-area layout of the reachable band (the planner indexes its candidates by
    these directions, so a changed bit would be a changed plan)."""
    lo, hi = arm.elevation_band(floor)
    want = np.array([arm.clamp_azimuth(d) for d in fibonacci_cap(n, lo, hi)])
    got = arm.homogeneous(n, floor)
    assert got.shape == (n, 3)
    np.testing.assert_array_equal(got, want)
    az, _ = az_el_from_direction(got)
    az = np.where(az > 180.0, az - 360.0, az)
    assert np.all(az >= arm.min_azimuth_deg - 1e-9) and np.all(az <= arm.max_azimuth_deg + 1e-9)
