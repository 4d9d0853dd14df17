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


def _noise_bound(lights: np.ndarray) -> float:
    """Photometric stereo's noise bound for a normal not known in advance, tr (LᵀL)⁻¹ (3 for
    three orthogonal lights, the least three can give)."""
    return float(np.trace(np.linalg.inv(lights.T @ lights)))


def _linearly_mapped_triad(arm: ArmGeometry) -> np.ndarray:
    """The triad as it had been placed before: 0°/120°/240° mapped linearly into the range."""
    from rti_rig.core.geometry import direction_from_az_el, even_layout

    lo, hi = arm.elevation_band()
    az, el = az_el_from_direction(even_layout(3, lo, hi))
    span = arm.max_azimuth_deg - arm.min_azimuth_deg
    return direction_from_az_el(arm.min_azimuth_deg + (_signed(az) + 180.0) * span / 360.0, el)


@pytest.mark.parametrize("half_span", [180.0, 170.0, 120.0])
def test_three_lights_are_the_exact_triad_where_the_range_holds_it(half_span: float) -> None:
    """From 240° of range the triad fits whole: turned to the range's middle, not squeezed."""
    arm = ArmGeometry(0.0, 90.0, 15.0, 0.0, 10.0, -half_span, half_span)
    lights = arm.homogeneous(3)
    np.testing.assert_allclose(lights.T @ lights, np.eye(3), atol=1e-12)
    assert arm.reachable(lights).all()


@pytest.mark.parametrize(
    ("low", "high"), [(-90.0, 90.0), (0.0, 180.0), (-60.0, 60.0), (-45.0, 45.0)]
)
def test_three_lights_on_a_narrow_arm_reach_its_limits(low: float, high: float) -> None:
    """Under 240° of range the triad cannot stand 120° apart: its ring is kept and its lights
    go to the range's two limits and its middle. Mapped linearly, they had stood at 1/6, 1/2
    and 5/6 of the range (-60°/0°/60° on an arm turning ±90°: noise bound 19 against 4.5)."""
    from rti_rig.core.geometry import ORTHOGONAL_TRIAD_ELEVATION_DEG

    arm = ArmGeometry(0.0, 90.0, 15.0, 0.0, 10.0, low, high)
    lights = arm.homogeneous(3)
    assert arm.reachable(lights).all()
    az, el = az_el_from_direction(lights)
    np.testing.assert_allclose(el, ORTHOGONAL_TRIAD_ELEVATION_DEG, atol=1e-9)
    np.testing.assert_allclose(np.sort(_signed(az)), [low, 0.5 * (low + high), high], atol=1e-9)
    assert _noise_bound(lights) < _noise_bound(_linearly_mapped_triad(arm)) / 3.0
    if (low, high) == (-90.0, 90.0):
        assert _noise_bound(lights) == pytest.approx(4.5)


def test_three_lights_on_a_narrow_arm_under_a_ceiling_stand_at_it() -> None:
    """A ceiling below 35.26° holds every light at the ceiling, spread over the range."""
    arm = ArmGeometry(0.0, 30.0, 15.0, 0.0, 10.0, -90.0, 90.0)
    az, el = az_el_from_direction(arm.homogeneous(3))
    np.testing.assert_allclose(el, 30.0, atol=1e-9)
    np.testing.assert_allclose(np.sort(_signed(az)), [-90.0, 0.0, 90.0], atol=0.01)


def test_the_ring_limit_is_the_fits() -> None:
    """The core restates the fit's condition limit (it imports nothing else of rti_rig)."""
    from rti_rig.core.geometry import TRIAD_RING_COND_LIMIT
    from rti_rig.reconstruct.solve import COND_LIMIT

    assert TRIAD_RING_COND_LIMIT == COND_LIMIT


@pytest.mark.parametrize("half", [16.0, 10.0, 2.0])
def test_three_lights_on_a_very_narrow_arm_raise_the_middle_one(half: float) -> None:
    """Under 34° of range three lights on one ring are too nearly on one great circle for the
    fit (condition number 112 at ±16°): the middle light goes to the top of the band, and the
    three determine a normal again."""
    from rti_rig.core.geometry import TRIAD_RING_COND_LIMIT

    arm = ArmGeometry(0.0, 90.0, 15.0, 0.0, 10.0, -half, half)
    lights = arm.homogeneous(3)
    assert arm.reachable(lights).all()
    az, el = az_el_from_direction(lights)
    np.testing.assert_allclose(np.sort(_signed(az)), [-half, 0.0, half], atol=1e-9)
    np.testing.assert_allclose(np.sort(el), [35.26, 35.26, 75.0], atol=0.01)
    assert np.linalg.cond(lights) < TRIAD_RING_COND_LIMIT


def test_the_ring_is_kept_while_it_determines_a_normal() -> None:
    """At ±17° the ring still passes the fit's limit (condition number 99), so it is kept."""
    arm = ArmGeometry(0.0, 90.0, 15.0, 0.0, 10.0, -17.0, 17.0)
    _, el = az_el_from_direction(arm.homogeneous(3))
    np.testing.assert_allclose(el, 35.26, atol=0.01)


def test_a_floor_above_the_arms_reach_says_how_low_it_must_be() -> None:
    """It named the reach but not the way out, where a ceiling below it says "raise it"."""
    from rti_rig.core.errors import ScheduleError

    with pytest.raises(ScheduleError, match=r"5°\.\.80°\): lower it below 80° \(--min-elevation"):
        ARMS[0].elevation_band(85.0)
