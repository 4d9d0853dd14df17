"""The full scale read from an acquisition's 16-bit codes (rti_rig.reconstruct.full_scale)."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.reconstruct.full_scale import PILE_MIN_PIXELS, full_scale_of

NAMES = [f"image_{i:03d}" for i in range(1, 9)]


def _scene(top: float, seed: int = 0) -> np.ndarray:
    """8 images × 4000 pixels × 3 channels of smoothly spread linear values up to ``top``."""
    rng = np.random.default_rng(seed)
    return rng.uniform(0.0, 1.0, (8, 4000, 3)) ** 2 * top


def test_a_pile_at_one_code_is_a_clip_whatever_the_code() -> None:
    """A 12-bit sensor less its black level of 256 clips at 3839: no depth's top code."""
    v = np.minimum(np.round(_scene(5000.0)), 3839).astype(np.uint16)
    got = full_scale_of(v, NAMES)
    assert got is not None and got.how == "clipped" and got.level == 3839, got
    assert got.bits is None
    assert got.clipped_image in NAMES and 0 < got.clipped_share < 1


def test_a_top_code_reached_by_a_few_pixels_is_no_clip() -> None:
    v = np.round(_scene(4000.0)).astype(np.uint16)
    v[3, 7, 1] = 4095  # one pixel, the brightest: no pile
    got = full_scale_of(v, NAMES)
    assert got is not None and got.how == "bits" and got.level == 4095 and got.bits == 12, got


def test_a_clip_needs_enough_pixels_at_the_top() -> None:
    v = np.minimum(np.round(_scene(3500.0)), 2999).astype(np.uint16)
    v[0, 0, 0] = 3000  # the code found below the top: one value
    v[2, : PILE_MIN_PIXELS - 1, 0] = 4095  # one short of a pile
    assert full_scale_of(v, NAMES).how == "bits"  # type: ignore[union-attr]
    v[2, :PILE_MIN_PIXELS, 0] = 4095
    assert full_scale_of(v, NAMES).how == "clipped"  # type: ignore[union-attr]


def test_dense_dark_codes_are_not_a_pile() -> None:
    """At low codes every value holds many pixels; the brightest holds fewer than the one
    below it unless something clipped there: 10-bit, not clipped."""
    v = np.round(_scene(900.0)).astype(np.uint16)
    got = full_scale_of(v, NAMES)
    assert got is not None and got.how == "bits" and got.level == 1023, got


def test_shifted_data_is_read_by_its_zero_low_bits() -> None:
    v = (np.round(_scene(3000.0)).astype(np.uint16) << 4).astype(np.uint16)
    got = full_scale_of(v, NAMES)
    assert got is not None and got.how == "shifted" and got.level == 65520 and got.bits == 12


@pytest.mark.parametrize("top", [65535.0, 40000.0])
def test_sixteen_bit_data_keeps_65535(top: float) -> None:
    v = np.round(_scene(top)).astype(np.uint16)
    v[0, 0, 0] = int(top)
    assert full_scale_of(v, NAMES) is None


def test_sixteen_bit_data_clipped_at_65535_keeps_it() -> None:
    v = np.minimum(np.round(_scene(90000.0)), 65535).astype(np.uint16)
    assert full_scale_of(v, NAMES) is None


def test_eight_bit_or_float_data_is_not_read() -> None:
    assert full_scale_of(np.zeros((2, 10, 3), np.uint8), NAMES) is None
    assert full_scale_of(np.zeros((2, 10, 3), np.float32), NAMES) is None


def test_a_lens_caps_noise_is_no_depth() -> None:
    """A capped lens's 16-bit frames (noise of a few codes) stay judged against 65535, where
    they are black; read as 10-bit data they had passed as a dark exposure."""
    rng = np.random.default_rng(1)
    v = np.clip(np.round(rng.normal(8.0, 3.0, (24, 4000, 3))), 0, None).astype(np.uint16)
    assert 0 < int(v.max()) <= 255
    assert full_scale_of(v, NAMES * 3) is None


def test_eight_bit_codes_times_257_are_no_clip_below_their_top() -> None:
    """A JPEG's codes made 16-bit (× 257) whose sample never reaches 255: its top code holds
    about as many pixels as the code below it that occurs (none lie between)."""
    rng = np.random.default_rng(2)
    codes = np.round(rng.uniform(0.0, 1.0, (8, 4000, 3)) * 230).astype(np.uint16)
    assert full_scale_of(codes * np.uint16(257), NAMES) is None


def test_ten_bit_data_shifted_into_a_twelve_bit_container_reads_as_twelve_bit() -> None:
    v = (np.round(_scene(900.0)).astype(np.uint16) << 2).astype(np.uint16)
    got = full_scale_of(v, NAMES)
    assert got is not None and got.how == "bits" and got.level == 4095, got


def test_fourteen_bit_range_without_a_clip_is_not_read() -> None:
    """A linear RAW export of a dark object stays under 16383 too: not read as 14-bit."""
    v = np.round(_scene(15000.0)).astype(np.uint16)
    assert full_scale_of(v, NAMES) is None
    v[1, :20, :] = 16383  # clipped there: a 14-bit clip is read
    got = full_scale_of(v, NAMES)
    assert got is not None and got.how == "clipped" and got.bits == 14, got
