"""The session's 8-bit sRGB JPEG pixels: the same codes as the formula, without its memory.

Writing each 24 MP frame's JPEG made five whole-image float32 temporaries (1.4 GB) in
``linear_to_srgb8``, the largest allocation of a simulated DSLR session after the camera's own.
The measure is tracemalloc's peak (numpy reports its buffers to it) in units of the uint16 image.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from rti_rig.core.image_files import _srgb_curve, linear_to_srgb8


def _formula(pixels: np.ndarray, white_level: float) -> np.ndarray:
    x = np.clip(pixels.astype(np.float32) / float(white_level), 0.0, 1.0)
    return np.round(_srgb_curve(x) * 255.0).astype(np.uint8)


@pytest.mark.parametrize("white_level", [65535, 16383, 4095, 1000])
def test_every_16_bit_value_gets_the_formula_code(white_level):
    values = np.arange(65536, dtype=np.uint16)
    np.testing.assert_array_equal(
        linear_to_srgb8(values, white_level), _formula(values, white_level)
    )
    image = np.random.default_rng(white_level).integers(0, 65536, (123, 77, 3)).astype(np.uint16)
    got = linear_to_srgb8(image, white_level)
    assert got.shape == image.shape and got.dtype == np.uint8
    np.testing.assert_array_equal(got, _formula(image, white_level))


def test_other_types_and_levels_still_go_through_the_formula():
    image = np.random.default_rng(1).integers(0, 4096, (20, 30)).astype(np.int32)
    np.testing.assert_array_equal(linear_to_srgb8(image, 4095), _formula(image, 4095))
    px = np.arange(0, 65536, 97, dtype=np.uint16)
    np.testing.assert_array_equal(linear_to_srgb8(px, 1000.5), _formula(px, 1000.5))


def test_encoding_a_frame_holds_little_more_than_its_8_bit_result():
    image = np.random.default_rng(2).integers(0, 65536, (600, 700, 3)).astype(np.uint16)
    linear_to_srgb8(image[:1], 65535)  # the table is made once per white level
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        linear_to_srgb8(image, 65535)
        peak = tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()
    # the uint8 result is half the uint16 image; the formula held ~5 float32 copies (10 images)
    assert peak < 1.0 * image.nbytes, peak / image.nbytes
