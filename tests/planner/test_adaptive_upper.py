"""The stop's upper estimate (``planner.adaptive_until``): the point estimate times the upper
factor, and a target is claimed only when the upper estimate is at most it."""

from __future__ import annotations

import pytest

from rti_rig.planner.adaptive_until import (
    UPPER_FACTOR,
    UPPER_QUANTILE,
    reaches_target,
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
