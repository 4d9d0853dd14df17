"""The QA's first pass (every pixel of every image) reduces a frame cheaply, to what it was.

At 24 MP the pass had cost about 1 s of CPU an image (48 images: most of a 60-85 s verdict),
in numpy's reductions over the channel axis and a full-resolution float grey image; it now
takes the channels' maximum elementwise and averages the channels after the area resize
(qa._reduced). These tests hold it to the full-resolution definition it replaced: the same
saturated fraction (any channel clipped), the same reduced grey image (to half a 16-bit code),
and the same reduced pixels marked as holding a clipped one, down to a lone pixel.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from rti_rig.reconstruct.qa import _reduced
from rti_rig.reconstruct.stack import channel_mean


def _by_definition(a: np.ndarray, saturation: float, shape: tuple[int, int]):  # type: ignore[no-untyped-def]
    m = np.any(a >= saturation, axis=-1) if a.ndim == 3 else a >= saturation
    f = np.asarray(a, dtype=np.float32)
    g = channel_mean(f) if f.ndim == 3 else f
    small = cv2.resize(g, shape, interpolation=cv2.INTER_AREA)
    small_sat = cv2.resize(m.astype(np.float32), shape, interpolation=cv2.INTER_AREA) > 0
    return float(m.mean()), small, small_sat


@pytest.mark.parametrize("channels", [None, 1, 3, 4])
def test_a_16_bit_frame_reduces_as_by_definition(channels: int | None) -> None:
    rng = np.random.default_rng(3)
    shape = (301, 457) if channels is None else (301, 457, channels)
    a = rng.integers(0, 60000, size=shape, dtype=np.uint16)
    a[17, 33, ...] = 65535  # a lone clipped pixel (every channel)
    if channels and channels > 1:
        a[200, 400, 1] = 65535  # one channel of another
    small_shape = (457 // 2, 301 // 2)  # (w, h); 301 / 150 is not a whole factor
    frac, small, small_sat = _reduced(a, 65535.0, small_shape)
    want = _by_definition(a, 65535.0, small_shape)
    assert frac == want[0]
    assert small.dtype == np.float32 and small.shape == want[1].shape
    np.testing.assert_allclose(small, want[1], atol=0.5)
    np.testing.assert_array_equal(small_sat, want[2])
    assert small_sat[17 // 2, 33 // 2]


def test_a_float_frame_with_a_nan_channel_still_counts_its_clipped_one() -> None:
    a = np.full((40, 60, 3), 0.25, dtype=np.float64)
    a[5, 7] = (np.nan, 2.0, 0.1)
    frac, small, small_sat = _reduced(a, 1.0, (30, 20))
    want = _by_definition(a, 1.0, (30, 20))
    assert frac == want[0] == 1 / (40 * 60)
    np.testing.assert_array_equal(small_sat, want[2])
    finite = np.isfinite(want[1])
    np.testing.assert_allclose(small[finite], want[1][finite], rtol=1e-6)


def test_a_frame_with_nothing_clipped_marks_no_reduced_pixel() -> None:
    a = np.random.default_rng(4).integers(0, 60000, size=(120, 90, 3), dtype=np.uint16)
    frac, small, small_sat = _reduced(a, 65535.0, (45, 60))
    want = _by_definition(a, 65535.0, (45, 60))
    assert frac == want[0] == 0.0
    assert small_sat.dtype == np.bool_ and small_sat.shape == small.shape == want[2].shape
    assert not small_sat.any()
