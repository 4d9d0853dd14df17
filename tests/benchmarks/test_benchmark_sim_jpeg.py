"""The 8-bit JPEG camera and the LED spread of benchmarks.planner_sim_jpeg.

The benchmark's verdict on ``--signal-noise`` for JPEG cameras rests on this being what a camera
does: the sRGB curve, 8 bits, JPEG, and back to linear without a colour swap; and on the LED
spread scaling the light before the camera, so a bright LED saturates as it would.
"""

from __future__ import annotations

import numpy as np

from benchmarks.planner_real_data import srgb_to_linear
from benchmarks.planner_sim_jpeg import jpeg_round_trip, led_factors
from benchmarks.tradeoff import TradeoffSettings, render_scene_data
from rti_rig.simulator.camera_model import to_srgb8


def _ramp() -> np.ndarray:
    """A smooth linear image (64×64×3) from black to 80 % of white, tinted per channel."""
    x = np.linspace(0.0, 0.8, 64)
    grey = np.tile(x, (64, 1))
    return np.stack([grey, 0.8 * grey, 0.6 * grey], axis=-1)


def test_round_trip_keeps_a_smooth_image_within_eight_bit_steps() -> None:
    img = _ramp()
    srgb8, linear = jpeg_round_trip(img)
    assert srgb8.dtype == np.uint8 and srgb8.shape == img.shape
    assert linear.dtype == np.float32 and linear.shape == img.shape
    # an 8-bit sRGB step at 80 % of white is ~0.008 in linear units; JPEG adds a little
    assert np.max(np.abs(linear - img)) < 0.02
    assert np.mean(np.abs(linear - img)) < 0.004


def test_linear_output_is_the_decoded_eight_bit_image_linearised() -> None:
    srgb8, linear = jpeg_round_trip(_ramp())
    np.testing.assert_allclose(linear, srgb_to_linear(srgb8 / 255.0), rtol=1e-6, atol=1e-7)


def test_jpeg_compression_is_applied_not_only_rounding() -> None:
    """On a textured image JPEG's blocks change values that plain 8-bit rounding keeps."""
    rng = np.random.default_rng(0)
    img = np.clip(0.4 + 0.2 * rng.standard_normal((64, 64, 3)), 0.0, 1.0)
    srgb8, _ = jpeg_round_trip(img)
    rounded = to_srgb8(img, 1).astype(int)
    assert np.mean(np.abs(srgb8.astype(int) - rounded)) > 2.0


def test_round_trip_keeps_channels_in_rgb_order() -> None:
    img = np.zeros((32, 32, 3))
    img[..., 0] = 0.7  # red only
    srgb8, linear = jpeg_round_trip(img)
    assert srgb8[..., 0].mean() > 200 and srgb8[..., 2].mean() < 30
    assert linear[..., 0].mean() > 0.6 and linear[..., 2].mean() < 0.05


def test_values_above_white_clip() -> None:
    img = _ramp() * 2.0
    srgb8, linear = jpeg_round_trip(img)
    assert linear.max() <= 1.0
    assert srgb8[..., 0][img[..., 0] > 1.2].min() >= 250


def test_grey_image_round_trips_as_grey() -> None:
    img = _ramp()[..., 0]
    srgb8, linear = jpeg_round_trip(img)
    assert srgb8.shape == img.shape and linear.shape == img.shape
    assert np.max(np.abs(linear - img)) < 0.02


def test_led_factors_have_the_stated_spread_and_none_without_it() -> None:
    assert np.array_equal(led_factors(5, 0.0, 3), np.ones(5))
    f = led_factors(4000, 0.05, 3)
    assert abs(np.std(np.log(f)) - 0.05) < 0.003 and abs(np.mean(np.log(f))) < 0.003
    assert np.array_equal(f, led_factors(4000, 0.05, 3))  # one fixed draw: one simulated dome


def test_candidate_irradiance_scales_the_light_before_the_camera() -> None:
    """Factors of 1 give render_scene_data's own images; a brighter LED is brighter and
    saturates at white, as in a camera, instead of being a clipped image scaled afterwards."""
    s = TradeoffSettings(
        scenes=("coin",), size_px=24, candidates=12, held_out_lights=1, ground_truth_lights=12
    )
    data = render_scene_data("coin", s)
    cand = data.candidate_dirs
    same = render_scene_data("coin", s, np.ones(len(cand))).candidate_images
    assert np.array_equal(same, data.candidate_images)
    bright = render_scene_data("coin", s, np.full(len(cand), 3.0)).candidate_images
    assert bright.max() == 1.0 and np.mean(bright >= 1.0) > np.mean(same >= 1.0)
    dark = render_scene_data("coin", s, np.full(len(cand), 0.5)).candidate_images
    lit = (same > 0.1) & (same < 0.9)
    assert abs(np.mean(dark[lit]) / np.mean(same[lit]) - 0.5) < 0.03
    # a saturated highlight dimmed by a factor below 1 reads below white, as a real LED would
    assert np.mean(dark >= 1.0) < np.mean(same >= 1.0)
