"""One shot tells whether an exposure chosen at one light keeps within the rule at another.

On a dome whose LEDs differ, the exposure metered at the light nearest the zenith clipped other
lights' images; ``recheck_exposure`` checks it at another light with one shot, and where that
light is brighter chooses a shorter one (never a longer one).
"""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.drivers.cameras.exposure import predicted_saturated_fraction, recheck_exposure
from rti_rig.drivers.cameras.raw_roundtrip import RawRoundTripCamera
from rti_rig.drivers.cameras.settings import ExposureRule

RULE = ExposureRule(max_saturated_fraction=0.002, headroom=1.25, max_attempts=6)


def _camera(peak_per_s: float, shots: list[float]) -> RawRoundTripCamera:
    """A ramp whose brightest pixels reach ``peak_per_s`` of full scale per second."""
    radiance = np.linspace(0.0, peak_per_s, 48 * 64 * 3).reshape(48, 64, 3)

    def render(t: float) -> np.ndarray:
        shots.append(t)
        return radiance * t

    cam = RawRoundTripCamera("sim", render)
    cam.connect()
    return cam


def test_a_light_no_brighter_costs_one_shot_and_changes_nothing() -> None:
    shots: list[float] = []
    choice, tested = recheck_exposure(_camera(5.0, shots), RULE, 0.1)  # peak 0.5 of white
    assert choice is None and tested == (0.1,) and shots == [0.1]


def test_a_light_within_the_limit_but_not_the_headroom_is_shortened_from_that_shot() -> None:
    shots: list[float] = []
    cam = _camera(9.0, shots)  # peak 0.9 of white at 0.1 s: 1.125 with the headroom
    choice, tested = recheck_exposure(cam, RULE, 0.1)
    assert choice is not None and choice.satisfied and tested == (0.1,) and shots == [0.1]
    assert choice.exposure_s < 0.1
    frame = cam.capture(0.1)
    assert predicted_saturated_fraction(frame, choice.exposure_s, 1.25) <= 0.002


def test_a_light_that_clips_is_metered_again_never_longer() -> None:
    shots: list[float] = []
    choice, tested = recheck_exposure(_camera(20.0, shots), RULE, 0.1)  # twice white
    assert choice is not None and choice.satisfied
    assert tested[0] == 0.1 and tested == tuple(shots) and len(tested) > 1
    assert max(shots[1:]) < 0.1 and choice.exposure_s < 0.1
    assert choice.test_exposures_s == tested
    assert choice.measured_saturated_fraction <= 0.002


def test_a_shutter_list_is_kept_to() -> None:
    shutters = [1 / 250, 1 / 125, 1 / 60, 1 / 30, 1 / 15, 1 / 8]
    shots: list[float] = []
    choice, tested = recheck_exposure(_camera(20.0, shots), RULE, 1 / 8, shutters)
    assert choice is not None and choice.exposure_s in shutters and choice.exposure_s < 1 / 8
    assert all(t in shutters for t in tested)
    # 1/30 s puts the ramp's top at 0.67 of white (0.83 with the headroom); 1/15 s clips
    assert choice.exposure_s == pytest.approx(1 / 30)
