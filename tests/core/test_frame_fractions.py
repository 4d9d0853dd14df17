"""A frame's saturated and black fractions: each pixel's largest channel, as ``max(axis=-1)``.

The channel maximum is taken channel against channel (faster than a reduction over a last
axis of 3); it must say what the plain reduction says, grey and colour, NaN included.
"""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.devices import Frame


def _frame(pixels: np.ndarray, white: int = 65535) -> Frame:
    return Frame(pixels=pixels, exposure_s=0.05, gain=1.0, white_level=white, timestamp_s=0.0)


@pytest.mark.parametrize("shape", [(40, 30), (40, 30, 1), (40, 30, 3), (40, 30, 4)])
def test_the_fractions_are_those_of_the_plain_channel_maximum(shape) -> None:  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(1)
    # codes bunched at both ends, so both fractions are well inside (0, 1)
    pixels = rng.choice(np.array([0, 0, 1, 40000, 65534, 65535], np.uint16), size=shape)
    frame = _frame(pixels)
    px = pixels if pixels.ndim == 2 else pixels.max(axis=-1)
    assert frame.saturated_fraction == float(np.mean(px >= 65535))
    assert frame.black_fraction == float(np.mean(px == 0))
    assert 0.0 < frame.saturated_fraction < 1.0 and 0.0 < frame.black_fraction < 1.0


def test_a_float_frame_with_nan_counts_as_the_reduction_does() -> None:
    pixels = np.array([[[0.0, 0.0, 0.0], [np.nan, 0.0, 1.0]], [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0]]])
    frame = _frame(pixels, white=2)
    px = pixels.max(axis=-1)
    assert frame.saturated_fraction == float(np.mean(px >= 2)) == 0.5
    assert frame.black_fraction == float(np.mean(px == 0)) == 0.25
    assert pixels[0, 1, 0] != pixels[0, 1, 0]  # the frame's pixels are not modified
