"""Streaming: tiles give the untiled result, and peak memory stays near one band."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from rti_rig.reconstruct import ImageStack, ReconstructionError, fit_model
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals
from rti_rig.reconstruct.tiling import row_tiles, rows_for_budget


def test_row_tiles_cover_every_row_once() -> None:
    tiles = list(row_tiles(10, 4))
    assert [(t.start, t.stop) for t in tiles] == [(0, 4), (4, 8), (8, 10)]
    with pytest.raises(ValueError):
        list(row_tiles(10, 0))


def test_rows_for_budget() -> None:
    # 100 lights × 6000 px × 3 channels × 4 bytes = 7.2 MB a row
    assert rows_for_budget(100, 6000, 3, budget_bytes=72_000_000) == 10
    assert rows_for_budget(100, 6000, 3, budget_bytes=1) == 1


@pytest.mark.parametrize("model", ["lambert", "hsh1", "ptm", "hsh2", "hsh3"])
def test_tiled_fit_equals_untiled(model: str) -> None:
    normals, _ = sphere_normals(23, 17)
    lights = fibonacci_lights(30)
    images = render(normals, np.full((23, 17, 3), 0.5), lights, specular=0.5)
    whole = fit_model(model, images, lights, tile_rows=1000)
    tiled = fit_model(model, images, lights, tile_rows=3)
    np.testing.assert_allclose(tiled.coefficients, whole.coefficients, rtol=1e-5, atol=1e-6)


def test_list_of_uint16_frames_equals_scaled_float_array() -> None:
    rng = np.random.default_rng(0)
    pixels = rng.integers(0, 65535, (12, 9, 8), dtype=np.uint16)
    lights = fibonacci_lights(12)
    from_list = fit_model("ptm", list(pixels), lights, tile_rows=2)
    from_float = fit_model("ptm", pixels.astype(np.float32) / 65535.0, lights)
    np.testing.assert_allclose(from_list.coefficients, from_float.coefficients, atol=1e-5)


def test_peak_memory_is_a_band_not_the_stack() -> None:
    """Fitting HSH2 from uint16 frames never builds the float32 stack (N × H × W × 4 bytes)."""
    n, h, w = 40, 256, 256
    frames = [np.full((h, w), 1000 + 10 * i, dtype=np.uint16) for i in range(n)]
    lights = fibonacci_lights(n)
    float_stack_bytes = n * h * w * 4
    coefficient_bytes = 9 * h * w * 4
    tracemalloc.start()
    try:
        model = fit_model("hsh2", frames, lights, tile_rows=8)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert model.coefficients.shape == (9, h, w)
    band_bytes = n * 8 * w * 4
    assert peak < coefficient_bytes + 4 * band_bytes + 1_000_000
    assert peak < float_stack_bytes / 2


def test_images_must_be_finite_and_consistent() -> None:
    lights = fibonacci_lights(6)
    images = np.ones((6, 4, 4), dtype=np.float32)
    images[3, 2, 1] = np.nan
    with pytest.raises(ReconstructionError, match="image 3 holds NaN"):
        ImageStack(images).rows(slice(0, 4))
    # a fit treats it as a missing observation: with 6 lights that pixel cannot be fitted by
    # PTM (6 coefficients) and is counted, every other pixel is fitted as usual
    fitted = fit_model("ptm", images, lights)
    assert fitted.report.pixels_unfitted == 1 and fitted.report.pixels_with_missing == 1
    assert np.all(fitted.coefficients[:, 2, 1] == 0)
    assert np.allclose(fitted.relight([0, 0, 1])[0, 0], 1.0, atol=1e-4)
    with pytest.raises(ReconstructionError, match="image 1 has shape"):
        ImageStack([np.ones((4, 4)), np.ones((4, 5))])
    with pytest.raises(ReconstructionError, match="shape"):
        ImageStack(np.ones((4, 4)))


@pytest.mark.slow
def test_robust_photometric_stereo_peak_memory_is_bounded_by_the_band() -> None:
    n, h, w = 40, 256, 256
    frames = [np.full((h, w), 1000 + 10 * i, dtype=np.uint16) for i in range(n)]
    lights = fibonacci_lights(n)
    # the compiled kernel loaded (or compiled) first: run alone, the test had counted numba's
    # compile (~40 MB of Python objects) as the fit's memory, and passed only after another test
    fit_model("ps-robust", [f[:4, :4] for f in frames], lights)
    tracemalloc.start()
    try:
        fit_model("ps-robust", frames, lights, tile_rows=8)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    outputs = h * w * (3 * 4 + 4 + 4 + 1 + 2)
    band_values = n * 8 * w
    reference_sample = 2 * n * 10_000 * 4  # the 99th-percentile sample behind the thresholds
    assert peak < outputs + 40 * band_values + reference_sample + 500_000
    assert peak < n * h * w * 4 * 0.75


def test_coefficients_can_stream_into_a_memmap(tmp_path) -> None:
    normals, _ = sphere_normals(20, 16)
    lights = fibonacci_lights(30)
    images = render(normals, np.full((20, 16, 3), 0.4), lights)
    out = np.lib.format.open_memmap(tmp_path / "hsh3.npy", "w+", np.float32, (16, 20, 16, 3))
    model = fit_model("hsh3", images, lights, tile_rows=5, out=out)
    assert model.coefficients is out
    out.flush()
    reread = np.load(tmp_path / "hsh3.npy")
    np.testing.assert_allclose(reread, fit_model("hsh3", images, lights).coefficients, atol=1e-6)
    with pytest.raises(ReconstructionError, match="out has shape"):
        fit_model("ptm", images, lights, out=np.zeros((6, 20, 16), np.float32))


@pytest.mark.parametrize("model", ["ptm", "hsh2"])
def test_coefficients_do_not_depend_on_the_band_size_to_the_bit(model: str) -> None:
    """A fit's exported bytes must not depend on the band size or the process that fitted a
    band (`rti-rig fit --scheduler`): float32 products summed by BLAS differ in the last bit
    with the number of columns, and a pixel near a quantisation boundary then flipped a byte
    of fit.ptm. JPEG-like levels with clipped observations exercise both paths (the product,
    and the per-pattern refit of pixels with a saturated observation)."""
    from rti_rig.core.rti_bases import design_matrix
    from rti_rig.reconstruct.linear_model import fit_coefficients

    rng = np.random.default_rng(0)
    lights = fibonacci_lights(36)
    levels = rng.integers(0, 256, (36, 30, 80, 3))
    linear = ((levels / 255 + 0.055) / 1.055) ** 2.4
    band = (np.round(linear * 65535) / 65535).astype(np.float32)
    design = design_matrix(model, lights)
    fits = [
        fit_coefficients(band, design, model, tile_rows=rows, saturation=1.0)[0]
        for rows in (3, 7, 30)
    ]
    for other in fits[1:]:
        assert np.array_equal(fits[0], other)
