"""Real dome data (a crop of the NeuralRTI example, MIT): conventions and sanity, no ground truth.

Two things synthetic data cannot show: that the docs/conventions.md frame (y up while image rows run
down) is the one the fitted normals live in, and that robust photometric stereo and model
choice behave on real, non-Lambertian pixels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from benchmarks.metrics import relight_psnr
from rti_rig.reconstruct import fit_model, fit_photometric_stereo, select_model

DATA = Path(__file__).resolve().parents[1] / "data" / "reconstruct_neuralrti" / "crop.npz"


@pytest.fixture(scope="module")
def dome() -> tuple[np.ndarray, np.ndarray]:
    with np.load(DATA) as z:
        srgb = z["images"].astype(np.float32) / 255.0
        lights = z["lights"]
    linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    return linear.astype(np.float32), lights / np.linalg.norm(lights, axis=1, keepdims=True)


def _mean_abs_curl(normals: np.ndarray, valid: np.ndarray, y_up: bool) -> float:
    """Non-integrability of the gradient field the normals imply, in image (row, col) axes."""
    n = normals.astype(np.float64)
    nz = np.maximum(n[..., 2], 0.2)
    dz_dcol = -n[..., 0] / nz
    dz_dy = -n[..., 1] / nz
    dz_drow = -dz_dy if y_up else dz_dy  # rows run down the image
    curl = np.gradient(dz_dcol, axis=0) - np.gradient(dz_drow, axis=1)
    return float(np.abs(curl[1:-1, 1:-1][valid[1:-1, 1:-1]]).mean())


def test_normals_are_integrable_in_the_design_frame(dome) -> None:
    """A real surface has a height: its normals' gradient field is curl-free only in the right
    frame. Reading y as pointing down the image makes it markedly less integrable."""
    images, lights = dome
    res = fit_photometric_stereo(images, lights, robust=True)
    assert res.valid.mean() > 0.95
    y_up = _mean_abs_curl(res.normals, res.valid, y_up=True)
    y_down = _mean_abs_curl(res.normals, res.valid, y_up=False)
    assert y_up < 0.8 * y_down


def test_robust_ps_and_model_choice_on_real_pixels(dome) -> None:
    images, lights = dome
    held = np.arange(len(lights)) % 6 == 0
    ls = fit_photometric_stereo(images[~held], lights[~held])
    rb = fit_photometric_stereo(images[~held], lights[~held], robust=True)
    assert rb.used_lights[rb.valid].mean() < len(lights[~held])  # something was discarded
    assert np.median(rb.residual[rb.valid]) < np.median(ls.residual)
    choice = select_model(images[~held], lights[~held])
    rows = {e.model: e for e in choice.evidence}
    assert rows[choice.model].rmse < rows["lambert"].rmse
    chosen = fit_model(choice.model, images[~held], lights[~held])
    lambert = fit_model("lambert", images[~held], lights[~held])
    assert relight_psnr(chosen, images[held], lights[held]) > relight_psnr(
        lambert, images[held], lights[held]
    )
