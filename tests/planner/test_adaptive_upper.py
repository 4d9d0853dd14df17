"""The stop's upper estimate (``planner.adaptive_until``): the point estimate times the upper
factor, and a target is claimed only when the upper estimate is at most it."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.planner.adaptive_until import (
    UNSOLVED_DEG,
    UPPER_FACTOR,
    UPPER_QUANTILE,
    reaches_target,
    unsolved_fraction,
    upper_error_deg,
)


def test_the_upper_estimate_is_the_point_times_the_factor() -> None:
    assert upper_error_deg(1.5) == pytest.approx(UPPER_FACTOR * 1.5)
    assert upper_error_deg(1.5, 3.0) == pytest.approx(4.5)
    assert UPPER_FACTOR > 1.0 and 0.5 < UPPER_QUANTILE <= 1.0  # an upper, not a point, factor


def test_a_target_is_claimed_only_when_the_upper_estimate_is_under_it() -> None:
    point = 1.0
    assert not reaches_target(point, point)  # the point estimate alone does not claim it
    assert not reaches_target(point, UPPER_FACTOR * point * 0.999)
    assert reaches_target(point, UPPER_FACTOR * point)
    assert reaches_target(point, 1.9, factor=1.9) and not reaches_target(point, 1.89, factor=1.9)


def test_the_unsolved_share_is_of_the_seen_pixels_the_fit_left_unsolved() -> None:
    assert unsolved_fraction(None) == 0.0  # no fit yet
    assert unsolved_fraction(np.zeros(0, dtype=bool)) == 0.0
    assert unsolved_fraction(np.ones(10, dtype=bool)) == 0.0
    assert unsolved_fraction(np.array([True, False, True, False])) == 0.5


def test_each_unsolved_pixel_adds_up_to_the_bound() -> None:
    """The upper estimate is point × factor + unsolved share × UNSOLVED_DEG (90°: the most a
    normal counted as facing the camera can be wrong), so that a sixth of a relief left
    unsolved by four grazing lights cannot be claimed at 1.5° on a small point estimate."""
    assert UNSOLVED_DEG == 90.0
    assert upper_error_deg(0.4, 1.95, 0.1) == pytest.approx(0.78 + 9.0)
    assert upper_error_deg(0.4, 1.95, 0.1, 45.0) == pytest.approx(0.78 + 4.5)
    assert upper_error_deg(0.4, 1.95, 0.0) == pytest.approx(0.78)
    assert reaches_target(0.36, 1.5, 1.95)  # the build before the term claimed this…
    assert not reaches_target(0.36, 1.5, 1.95, 0.17)  # …with 17 % of the pixels unsolved
    assert reaches_target(0.36, 1.5, 1.95, 0.17, 0.0)  # a session that weighs them at 0°
