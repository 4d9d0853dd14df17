"""The QA's banded medians give numpy's own medians, values and type, over several bands."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.reconstruct.qa_bands import BAND_VALUES, median_by_rows, median_of_images


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32, np.float64])
def test_banded_medians_are_numpys(dtype: type) -> None:
    n, h, w = 20, 300, 300
    assert n * h * w > BAND_VALUES  # more than one band
    stack = (np.random.default_rng(1).random((n, h, w)) * 250).astype(dtype)
    want = np.median(stack, axis=0)
    for got in (median_by_rows(stack), median_of_images(list(stack))):
        assert got.dtype == want.dtype  # a uint8 stack's median had been made float16
        assert np.array_equal(got, want)
