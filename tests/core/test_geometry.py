"""Frame conversions: exact round trips, and stable at the zenith and the horizon."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rti_rig.core.geometry import (
    angle_between_deg,
    az_el_from_direction,
    direction_from_az_el,
    fibonacci_cap,
    normalize,
    pixel_to_frame_xy,
)

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


@given(st.tuples(finite, finite, finite).filter(lambda v: np.linalg.norm(v) > 1e-6))
def test_direction_round_trip(v: tuple[float, float, float]) -> None:
    az, el = az_el_from_direction(v)
    assert 0.0 <= az < 360.0
    assert -90.0 <= el <= 90.0
    back = direction_from_az_el(az, el)
    np.testing.assert_allclose(back, normalize(v), atol=1e-12)


@given(st.floats(0.0, 359.999), st.floats(-89.9, 89.9))
def test_angles_round_trip(az: float, el: float) -> None:
    az2, el2 = az_el_from_direction(direction_from_az_el(az, el))
    assert el2 == pytest.approx(el, abs=1e-9)
    assert (az2 - az + 180.0) % 360.0 - 180.0 == pytest.approx(0.0, abs=1e-9)


@given(st.floats(0.0, 360.0))
def test_zenith_is_finite_and_azimuth_zero(az: float) -> None:
    d = direction_from_az_el(az, 90.0)
    a, e = az_el_from_direction(d)
    assert np.isfinite(a) and np.isfinite(e)
    assert e == pytest.approx(90.0, abs=1e-9)
    a0, e0 = az_el_from_direction([0.0, 0.0, 1.0])
    assert a0 == 0.0 and e0 == 90.0


def test_near_zenith_keeps_precision() -> None:
    # 1e-9 degrees off the axis: asin/acos based formulas lose this; atan2 keeps it.
    d = direction_from_az_el(30.0, 90.0 - 1e-9)
    az, el = az_el_from_direction(d)
    assert az == pytest.approx(30.0, abs=1e-3)
    assert 90.0 - el == pytest.approx(1e-9, rel=1e-3)


@given(st.floats(0.0, 359.999))
def test_horizon(az: float) -> None:
    d = direction_from_az_el(az, 0.0)
    assert d[2] == pytest.approx(0.0, abs=1e-15)
    _, e = az_el_from_direction(d)
    assert e == pytest.approx(0.0, abs=1e-12)
    tiny = direction_from_az_el(az, 1e-8)
    assert az_el_from_direction(tiny)[1] == pytest.approx(1e-8, rel=1e-6)


def test_frame_axes() -> None:
    np.testing.assert_allclose(direction_from_az_el(0, 0), [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(direction_from_az_el(90, 0), [0, 1, 0], atol=1e-15)
    # Image rows run down, frame y runs up: row 0 is the top (positive y).
    xy = pixel_to_frame_xy([0, 9], [0, 9], 10, 10)
    np.testing.assert_allclose(xy, [[-4.5, 4.5], [4.5, -4.5]])


def test_bad_vectors_rejected() -> None:
    with pytest.raises(ValueError, match="zero-length"):
        normalize([0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="NaN"):
        normalize([np.nan, 0.0, 1.0])


def test_angle_between_small_and_opposite() -> None:
    assert angle_between_deg([1, 0, 0], [1, 1e-10, 0]) == pytest.approx(np.degrees(1e-10))
    assert angle_between_deg([0, 0, 1], [0, 0, -1]) == pytest.approx(180.0)


@pytest.mark.parametrize("n", [1, 7, 100])
def test_fibonacci_cap_band(n: int) -> None:
    d = fibonacci_cap(n, 15.0, 80.0)
    _, el = az_el_from_direction(d)
    assert d.shape == (n, 3)
    assert np.all(el >= 15.0) and np.all(el <= 80.0)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0)


def test_three_lights_are_the_orthogonal_triad() -> None:
    """Three mutually orthogonal lights minimise photometric stereo's noise for a normal not
    known in advance: ``LᵀL`` is the identity, and the three stand 120° apart at 35.26°."""
    from rti_rig.core.geometry import ORTHOGONAL_TRIAD_ELEVATION_DEG, even_layout

    lights = even_layout(3)
    np.testing.assert_allclose(lights.T @ lights, np.eye(3), atol=1e-12)
    az, el = az_el_from_direction(lights)
    np.testing.assert_allclose(el, ORTHOGONAL_TRIAD_ELEVATION_DEG, atol=1e-9)
    np.testing.assert_allclose(np.sort(az), [0.0, 120.0, 240.0], atol=1e-9)


@pytest.mark.parametrize(("band", "expected"), [((0, 90), 35.26), ((50, 80), 50), ((0, 30), 30)])
def test_three_lights_keep_to_the_band(band: tuple[float, float], expected: float) -> None:
    """A band that leaves out 35.26° gets the triad at its nearest edge, still 120° apart."""
    from rti_rig.core.geometry import even_layout

    az, el = az_el_from_direction(even_layout(3, *band))
    np.testing.assert_allclose(el, expected, atol=0.01)
    np.testing.assert_allclose(np.sort(az), [0.0, 120.0, 240.0], atol=1e-9)


@pytest.mark.parametrize("n", [1, 2, 4, 6, 12, 48])
def test_other_counts_are_the_equal_area_spiral(n: int) -> None:
    from rti_rig.core.geometry import even_layout

    np.testing.assert_array_equal(even_layout(n, 10.0, 80.0), fibonacci_cap(n, 10.0, 80.0))
