"""The one judgement of whether exposure ranges share an exposure, and which ends bound what
they share (:mod:`rti_rig.core.exposure_range`): the config check at load and the metering's
start both call it (their agreement is tested in
tests/cli/test_config_camera_exposure_ranges.py)."""

from __future__ import annotations

import pytest

from rti_rig.core.exposure_range import longer_than, shared_range

CAMERA = ((0.001, "[camera] min"), (0.5, "[camera] max"))
DEVICE = ((0.0001, "device min"), (0.01, "device max"))


def test_the_tighter_end_of_each_side_bounds_the_share_and_is_the_one_given() -> None:
    shared = shared_range(CAMERA, DEVICE)
    assert shared.floor is CAMERA[0] and shared.cap is DEVICE[1]  # the objects given: by key
    assert not shared.empty


def test_ranges_that_do_not_meet_share_nothing_and_name_the_ends_apart() -> None:
    device = ((1.0, "device min"), (30.0, "device max"))
    shared = shared_range(CAMERA, device)
    assert shared.empty
    assert shared.floor is device[0] and shared.cap is CAMERA[1]


def test_ranges_that_meet_in_one_exposure_share_it() -> None:
    device = ((0.5, "device min"), (30.0, "device max"))
    assert not shared_range(CAMERA, device).empty
    # ... also where the two spellings differ only in their last bits (0.1 * 5 != 0.5)
    device = ((0.1 * 5 * (1 + 1e-12), "device min"), (30.0, "device max"))
    assert not shared_range(CAMERA, device).empty


def test_on_a_tie_the_range_given_first_is_said() -> None:
    other = ((0.001, "other min"), (0.5, "other max"))
    shared = shared_range(CAMERA, other)
    assert shared.floor is CAMERA[0] and shared.cap is CAMERA[1]
    shared = shared_range(other, CAMERA)
    assert shared.floor is other[0] and shared.cap is other[1]


def test_an_end_not_known_leaves_the_other_ranges_end() -> None:
    shared = shared_range((None, (0.05, "frame period")), (None, None), CAMERA)
    assert shared.floor is CAMERA[0] and shared.cap[0] == 0.05  # type: ignore[index]
    assert shared_range((None, None)).floor is None and not shared_range((None, None)).empty


@pytest.mark.parametrize(
    ("value", "above"), [(0.5, False), (0.5 * (1 + 1e-12), False), (0.51, True)]
)
def test_longer_than_allows_for_rounding_only(value: float, above: bool) -> None:
    assert longer_than(value, (0.5, "cap")) is above
