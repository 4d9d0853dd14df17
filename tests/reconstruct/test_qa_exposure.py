"""The exposure check's ratio (pure): judged only against at least two mates that agree."""

from __future__ import annotations

import numpy as np

from rti_rig.reconstruct.qa_exposure import exposure_off, exposure_ratios


def _lights(elevations_deg: list[float]) -> np.ndarray:
    el = np.radians(elevations_deg)
    az = np.radians(np.arange(len(el)) * 97.0)
    return np.c_[np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)]


def test_a_halved_image_of_a_ring_reads_half_and_its_mates_are_not_judged() -> None:
    lt = _lights([25, 25, 25, 55, 55, 55])
    level = np.array([0.2, 0.2, 0.1, 0.4, 0.42, 0.38])
    ratio, mates = exposure_ratios(level, lt, np.ones(6, bool))
    assert abs(ratio[2] - 0.5) < 1e-9 and mates[2] == 2
    assert exposure_off(ratio[2])
    # each correct 25° image has the halved one among its two mates, which disagree: unjudged
    assert np.isnan(ratio[0]) and np.isnan(ratio[1])
    assert not any(exposure_off(r) for r in ratio[3:])


def test_too_few_or_disagreeing_mates_judge_nothing() -> None:
    lt = _lights([10, 10, 40, 40, 40])
    level = np.array([0.1, 0.3, 0.1, 0.5, 0.2])  # the 40° mates differ 2.5× (a tilted object)
    ratio, _ = exposure_ratios(level, lt, np.ones(5, bool))
    assert np.isnan(ratio).all()


def test_an_unusable_mate_is_no_mate() -> None:
    lt = _lights([40, 40, 40, 40])
    level = np.array([0.2, 0.2, 0.4, 0.0])  # image 3 black (a misfire found already)
    usable = np.array([True, True, True, False])
    ratio, mates = exposure_ratios(level, lt, usable)
    assert mates[2] == 2 and abs(ratio[2] - 2.0) < 1e-9 and exposure_off(ratio[2])


def test_levels_are_compared_per_unit_of_the_lights_height() -> None:
    # a matte surface facing the camera at 6°, 8° and 10° (an arm's lights): each level is
    # its light's height, and the lowest is not "1.5× too dark" for it (it read 0.65)
    lt = _lights([6, 8, 10])
    level = 0.8 * lt[:, 2]
    ratio, _ = exposure_ratios(level, lt, np.ones(3, bool))
    assert np.allclose(ratio, 1.0)
