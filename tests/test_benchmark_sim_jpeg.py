"""The 8-bit JPEG camera of benchmarks.planner_sim_jpeg.

The benchmark's verdict on ``--signal-noise`` for JPEG cameras rests on this round trip being
what a camera does: the sRGB curve, 8 bits, JPEG, and back to linear without a colour swap or a
lost gain.
"""

from __future__ import annotations

import numpy as np

from benchmarks.planner_sim_jpeg import jpeg_round_trip


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
    # an 8-bit sRGB step at 80 % of white is ~0.006 in linear units; JPEG adds a little
    assert np.max(np.abs(linear - img)) < 0.02
    assert np.mean(np.abs(linear - img)) < 0.004
    # and it is 8-bit: far fewer distinct values than the input
    assert len(np.unique(srgb8[..., 0])) <= 64


def test_round_trip_keeps_channels_in_rgb_order() -> None:
    img = np.zeros((32, 32, 3))
    img[..., 0] = 0.7  # red only
    srgb8, linear = jpeg_round_trip(img)
    assert srgb8[..., 0].mean() > 200 and srgb8[..., 2].mean() < 30
    assert linear[..., 0].mean() > 0.6 and linear[..., 2].mean() < 0.05


def test_gain_scales_the_light_and_clips_at_white() -> None:
    img = _ramp()
    _, base = jpeg_round_trip(img)
    _, brighter = jpeg_round_trip(img, gain=1.1)
    mid = (img[..., 0] > 0.2) & (img[..., 0] < 0.7)
    ratio = brighter[..., 0][mid].mean() / base[..., 0][mid].mean()
    assert abs(ratio - 1.1) < 0.01
    _, clipped = jpeg_round_trip(img, gain=2.0)
    assert clipped.max() <= 1.0 and clipped[..., 0][img[..., 0] > 0.6].min() > 0.97


def test_grey_image_round_trips_as_grey() -> None:
    img = _ramp()[..., 0]
    srgb8, linear = jpeg_round_trip(img)
    assert srgb8.shape == img.shape and linear.shape == img.shape
    assert np.max(np.abs(linear - img)) < 0.02
