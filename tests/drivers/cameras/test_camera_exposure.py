"""The exposure rule: pure choice from a linear preview, and metering through a real decode."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rti_rig.core.devices import Frame
from rti_rig.drivers.cameras.exposure import (
    choose_exposure,
    choose_from_series,
    meter_exposure,
    predicted_saturated_fraction,
)
from rti_rig.drivers.cameras.raw_roundtrip import RawRoundTripCamera
from rti_rig.drivers.cameras.settings import ExposureRule, RawDecodeSettings


def ramp_frame(exposure_s=0.01, white=1000) -> Frame:
    """1000 pixels with values 0..999: at scale k, pixels >= white/k saturate."""
    px = np.arange(1000, dtype=np.uint16).reshape(25, 40)
    return Frame(pixels=px, exposure_s=exposure_s, gain=1.0, white_level=white, timestamp_s=0.0)


def test_prediction_scales_linearly_and_keeps_saturated_pixels():
    f = ramp_frame()
    assert predicted_saturated_fraction(f, 0.01) == 0.0
    assert predicted_saturated_fraction(f, 0.02) == pytest.approx(0.5)  # 500..999
    assert predicted_saturated_fraction(f, 0.02, headroom=2.0) == pytest.approx(0.75)
    sat = Frame(
        pixels=np.array([[1000, 10]], np.uint16),
        exposure_s=1.0,
        gain=0.0,
        white_level=1000,
        timestamp_s=0.0,
    )
    assert predicted_saturated_fraction(sat, 0.001) == 0.5  # unknown true value: stays clipped


def test_discrete_candidates_pick_the_longest_within_the_limit():
    rule = ExposureRule(max_saturated_fraction=0.01)
    choice = choose_exposure(ramp_frame(), rule, [0.01, 0.0101, 0.0102, 0.02])
    assert choice.satisfied
    assert choice.exposure_s == 0.0101  # 9 pixels clip; 0.0102 would clip 19
    assert choice.predicted_saturated_fraction == pytest.approx(0.009)
    manifest = choice.to_manifest()
    assert json.loads(json.dumps(manifest))["exposure_s"] == 0.0101
    assert manifest["rule"]["max_saturated_fraction"] == 0.01


def test_continuous_choice_sits_on_the_limit():
    rule = ExposureRule(max_saturated_fraction=0.01)
    f = ramp_frame()
    choice = choose_exposure(f, rule)
    t = choice.exposure_s
    assert choice.satisfied
    assert predicted_saturated_fraction(f, t) <= 0.01
    assert predicted_saturated_fraction(f, t * 1.001) > 0.01
    halved = choose_exposure(f, ExposureRule(max_saturated_fraction=0.01, headroom=2.0))
    assert halved.exposure_s == pytest.approx(t / 2, rel=1e-4)


def test_continuous_choice_is_clamped_to_the_rule_range():
    dark = Frame(
        pixels=np.zeros((4, 4), np.uint16),
        exposure_s=0.01,
        gain=0.0,
        white_level=1000,
        timestamp_s=0.0,
    )
    assert choose_exposure(dark, ExposureRule(max_exposure_s=2.0)).exposure_s == 2.0


def test_unsatisfiable_cases_say_what_to_do():
    sat = Frame(
        pixels=np.full((4, 4), 1000, np.uint16),
        exposure_s=0.01,
        gain=0.0,
        white_level=1000,
        timestamp_s=0.0,
    )
    c = choose_exposure(sat, ExposureRule(), [0.001, 0.01])
    assert not c.satisfied and "shorter preview" in c.reason and c.exposure_s == 0.001
    bright = ramp_frame(exposure_s=0.01)
    c = choose_exposure(bright, ExposureRule(max_saturated_fraction=0.0), [0.05, 0.1])
    assert not c.satisfied and "dim the light" in c.reason
    with pytest.raises(ValueError, match="no candidate"):
        choose_exposure(bright, ExposureRule(max_exposure_s=1.0), [5.0])


def test_choose_from_series_uses_measurements():
    def shot(t, frac):
        px = np.zeros(100, np.uint16)
        px[: int(frac * 100)] = 1000
        return Frame(
            pixels=px.reshape(10, 10), exposure_s=t, gain=0.0, white_level=1000, timestamp_s=0.0
        )

    rule = ExposureRule(max_saturated_fraction=0.05)
    c = choose_from_series([shot(0.1, 0.2), shot(0.05, 0.04), shot(0.02, 0.0)], rule)
    assert c.satisfied and c.exposure_s == 0.05 and c.measured_saturated_fraction == 0.04
    assert c.test_exposures_s == (0.02, 0.05, 0.1)
    c = choose_from_series([shot(0.1, 0.2)], rule)
    assert not c.satisfied and c.exposure_s == 0.1


def test_meter_exposure_through_the_raw_path_converges_and_verifies(tmp_path):
    rng = np.random.default_rng(3)
    radiance = rng.uniform(0.0, 1.0, size=(48, 64, 3)) ** 2 * 4.0  # full scale per second
    shots: list[float] = []

    def render(t):
        shots.append(t)
        return radiance * t

    cam = RawRoundTripCamera("sim", render, RawDecodeSettings(mode="mosaic"), output_dir=tmp_path)
    cam.connect()
    rule = ExposureRule(max_saturated_fraction=0.002, max_attempts=5)
    choice = meter_exposure(cam, rule, start_exposure_s=2.0)
    assert choice.satisfied and choice.method == "test-series"
    assert choice.measured_saturated_fraction <= 0.002
    assert len(shots) <= rule.max_attempts and shots[0] == 2.0
    assert choice.test_exposures_s[-1] == choice.exposure_s
    # close to the true optimum: the mosaic's 99.8th percentile reaches white
    from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic

    mosaic_radiance = linear_to_mosaic(radiance / 4.0, "RGGB", 0, 65535) / 65535 * 4.0
    optimum = 1.0 / np.quantile(mosaic_radiance, 1 - 0.002)
    assert optimum * 0.97 <= choice.exposure_s <= optimum * 1.001
    assert len(list(tmp_path.glob("cap*.dng"))) == len(shots)


def test_meter_exposure_with_camera_shutter_list(tmp_path):
    radiance = np.linspace(0.0, 10.0, 48 * 64 * 3).reshape(48, 64, 3)
    cam = RawRoundTripCamera("sim", lambda t: radiance * t)
    cam.connect()
    shutters = [1 / 250, 1 / 125, 1 / 60, 1 / 30, 1 / 15, 1 / 8, 1 / 4]
    choice = meter_exposure(cam, ExposureRule(max_saturated_fraction=0.01), 1 / 4, shutters)
    # brightest 1% of the ramp is above 9.9: 1/15 s puts it at 0.66 of full scale, 1/8 s clips
    assert choice.satisfied and choice.exposure_s == 1 / 15


def test_meter_exposure_validates_its_arguments():
    cam = RawRoundTripCamera("sim", lambda t: np.full((32, 32, 3), t))
    cam.connect()
    with pytest.raises(ValueError, match="backoff"):
        meter_exposure(cam, ExposureRule(), 0.1, backoff=1.5)


def test_meter_exposure_starts_at_the_offered_exposure_nearest_the_asked_one():
    """A start the camera does not offer (the config's 0.125 s on a body without 1/8 s) had
    raised a ValueError, which `rti-rig run --auto-exposure` printed as "unexpected ValueError
    ... please report it" before its first test shot."""
    radiance = np.linspace(0.0, 10.0, 48 * 64 * 3).reshape(48, 64, 3)
    cam = RawRoundTripCamera("sim", lambda t: radiance * t)
    cam.connect()
    shutters = [1 / 250, 1 / 125, 1 / 60, 1 / 30, 1 / 15, 1 / 10, 1 / 4]  # no 1/8
    choice = meter_exposure(cam, ExposureRule(max_saturated_fraction=0.01), 0.125, shutters)
    assert choice.test_exposures_s[0] == 1 / 10  # the nearest in stops
    assert choice.satisfied and choice.exposure_s == 1 / 10  # the top 1% at 0.99 of full scale
    assert all(t in shutters for t in choice.test_exposures_s)


def test_meter_exposure_gives_up_when_even_the_shortest_shot_saturates():
    cam = RawRoundTripCamera("sim", lambda t: np.full((32, 32, 3), 1000.0 * t))
    cam.connect()
    rule = ExposureRule(max_saturated_fraction=0.01, min_exposure_s=1e-3, max_attempts=10)
    choice = meter_exposure(cam, rule, 0.1)
    assert not choice.satisfied
    assert choice.exposure_s == pytest.approx(1e-3)
    assert choice.test_exposures_s == pytest.approx((1e-3, 1.5625e-3, 6.25e-3, 0.025, 0.1))
