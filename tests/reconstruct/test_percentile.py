"""The reference level's percentile, computed part by part (rti_rig.reconstruct.percentile), is
exactly the percentile of all the values; and a fit that streams its sample for it gets the
level it got from the held sample (issue #29: the sample is 22 MB of a 108 MB budget)."""

from __future__ import annotations

import os
import tempfile

import numpy as np
import pytest

from rti_rig.core.raw_rows import RawRows
from rti_rig.reconstruct.percentile import TopValues, percentile, values_needed
from rti_rig.reconstruct.stack import ImageStack


def _whole(values: np.ndarray, q: float) -> float:
    """The former computation: one partition of a copy of all the finite values."""
    v = values[np.isfinite(values)]
    if v.size == 0:
        return 0.0
    pos = q / 100.0 * (v.size - 1)
    lo = int(np.floor(pos))
    part = np.partition(v, lo)
    a = float(part[lo])
    if lo + 1 >= v.size:
        return a
    return a + (float(part[lo + 1 :].min()) - a) * (pos - lo)


@pytest.mark.parametrize("n", [1, 2, 7, 99, 100, 101, 1000, 20_011])
@pytest.mark.parametrize("chunk", [1, 5, 64, 1 << 20])
def test_part_by_part_is_the_percentile_of_the_whole(n: int, chunk: int) -> None:
    rng = np.random.default_rng(n * 31 + chunk)
    values = rng.random(n).astype(np.float32)
    values[: n // 3] = np.round(values[: n // 3] * 4) / 4  # ties
    if n > 5:
        values[rng.integers(0, n, n // 10)] = np.nan
        values[rng.integers(0, n, 2)] = np.inf
    for q in (99.0, 90.0, 50.0):
        got = percentile(values, q, chunk)
        assert got == _whole(values, q)
        finite = values[np.isfinite(values)]
        assert got == pytest.approx(float(np.percentile(finite.astype(np.float64), q)), abs=1e-6)


def test_nothing_finite_is_zero_and_too_few_kept_values_are_refused() -> None:
    assert percentile(np.full(10, np.nan, np.float32), 99.0) == 0.0
    top = TopValues(keep=2)
    top.add(np.arange(1000, dtype=np.float32))
    with pytest.raises(ValueError):
        top.percentile(50.0)  # needs 500 values above the median
    assert values_needed(1000, 99.0) <= values_needed(1001, 99.0)


def _raw_frames(images: np.ndarray) -> list[RawRows]:
    store = tempfile.TemporaryFile()  # noqa: SIM115 - kept open by the frames
    size = images[0].nbytes
    for k, img in enumerate(images):
        os.pwrite(store.fileno(), img.tobytes(), k * size)
    return [RawRows(store, k * size, images.shape[1:], images.dtype) for k in range(len(images))]


def test_a_streamed_reference_level_is_the_held_samples_and_holds_nothing() -> None:
    """A file-backed stack (frames read by rows, as the fit opens them): the level streamed
    with ``keep_sample=False`` equals the level of the held sample, and no sample is cached."""
    rng = np.random.default_rng(2)
    images = rng.integers(0, 65536, (9, 41, 37, 3), dtype=np.uint16)
    images[2, 5:9] = 65535  # saturated rows: counted like any value, as before
    streamed = ImageStack(_raw_frames(images))
    level = streamed.reference_level(500, keep_sample=False)
    assert streamed._samples == {}
    held = ImageStack(_raw_frames(images))
    assert level == held.reference_level(500)
    assert 500 in held._samples  # the default keeps it for the next reader (model choice)
    values, _ = held.pixel_sample(500)
    assert level == _whole(values.reshape(-1), 99.0)
