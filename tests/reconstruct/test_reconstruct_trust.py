"""Numerics that say when they cannot be trusted (issue #29): one test per audit finding.

Each test failed on the fitting code before the fix: conditioning judged over the given lights,
silent regularisation, saturation ignored by least squares and float input, one NaN aborting a
fit, the biased PTM normal estimator.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from rti_rig.reconstruct import (
    ReconstructionError,
    fit_hsh,
    fit_lambert,
    fit_photometric_stereo,
    fit_ptm,
)
from rti_rig.reconstruct.errors import (
    FitTrustWarning,
    IllConditionedFitWarning,
    RegularisedFitWarning,
)
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals


def _ring(elevation_deg: float, n: int, offset_deg: float = 0.0) -> np.ndarray:
    az = np.radians(np.arange(n) * 360.0 / n + offset_deg)
    el = np.radians(elevation_deg)
    return np.stack(
        [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.full(n, np.sin(el))], axis=1
    )


def _rings(elevations: list[float], n: int = 8) -> np.ndarray:
    return np.concatenate([_ring(e, n, 7.0 * e) for e in elevations])


def _angle_deg(a: np.ndarray, b: np.ndarray, mask: np.ndarray) -> float:
    cos = np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)
    return float(np.degrees(np.arccos(cos))[mask].mean())


def test_bunched_ptm_lights_are_judged_over_the_hemisphere_and_warned() -> None:
    lights = _rings([80, 82, 84, 86, 88])
    images = np.random.default_rng(0).uniform(0.2, 0.6, (len(lights), 3, 3)).astype(np.float32)
    with pytest.warns(IllConditionedFitWarning, match="noise"):
        model = fit_ptm(images, lights)
    assert model.report.noise_gain > 10
    assert model.report.warnings and not model.report.trusted
    # the same count of well-spread lights: no warning, small gain
    with warnings.catch_warnings():
        warnings.simplefilter("error", FitTrustWarning)
        spread = fit_ptm(images, fibonacci_lights(len(lights)))
    assert spread.report.trusted and spread.report.noise_gain < 1.5


@pytest.mark.parametrize(
    "case",
    ["hsh3 two rings 30/31", "ptm three lights repeated", "hsh3 cap 85-89"],
)
def test_regularised_fits_warn_by_name_and_record_it(case: str) -> None:
    if case.startswith("hsh3 two"):
        lights = np.concatenate([_ring(30, 12), _ring(31, 12, 15)])
    elif case.startswith("ptm"):
        lights = np.concatenate([fibonacci_lights(3)] * 2)
    else:
        lights = _rings([85, 86, 87, 88, 89])
    images = np.full((len(lights), 2, 2), 0.5, np.float32)
    with pytest.warns(RegularisedFitWarning, match="ridge-regularised"):
        model = fit_ptm(images, lights) if case.startswith("ptm") else fit_hsh(images, lights, 3)
    assert model.report.regularised and any("regularised" in w for w in model.report.warnings)


def test_fit_lambert_refuses_the_near_zenith_set_photometric_stereo_refuses() -> None:
    lights = _rings([89.0, 89.5, 89.9])
    images = np.full((len(lights), 2, 2), 0.5, np.float32)
    with pytest.raises(ReconstructionError, match="ill-conditioned"):
        fit_photometric_stereo(images, lights)
    with pytest.raises(ReconstructionError, match="ill-conditioned"):
        fit_lambert(images, lights)


def test_least_squares_ps_honours_saturation_of_integer_input() -> None:
    lights = fibonacci_lights(12)
    images = np.full((12, 4, 4), 65535, np.uint16)
    result = fit_photometric_stereo(images, lights)
    assert not result.valid.any()


def _clipped_sphere(clip: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    normals, inside = sphere_normals(48, 48)
    lights = fibonacci_lights(30, 20.0)
    images = np.minimum(render(normals, 0.8, lights), np.float32(clip))
    return images, lights, normals, inside


@pytest.mark.parametrize("robust", [False, True])
def test_float_input_saturation_honoured_by_photometric_stereo(robust: bool) -> None:
    images, lights, normals, inside = _clipped_sphere(0.5)
    result = fit_photometric_stereo(images, lights, robust=robust, saturation=0.5, shadow_k=None)
    # least squares has no shadow handling: compare on pixels lit by every light
    lit_all = inside & np.all(np.einsum("hwk,nk->nhw", normals, lights) > 0, axis=0)
    assert _angle_deg(result.normals, normals, lit_all & result.valid) < 0.5


def test_float_input_saturation_honoured_by_linear_fits() -> None:
    lights = fibonacci_lights(30, 20.0)
    truth = np.array([-0.1, -0.05, 0.02, 0.2, -0.1, 0.5])  # a PTM that exceeds 0.6 somewhere
    from rti_rig.core.rti_bases import ptm_basis

    values = (ptm_basis(lights) @ truth).astype(np.float32)
    images = np.minimum(values, np.float32(0.6))[:, None, None] * np.ones((1, 2, 2), np.float32)
    assert (values >= 0.6).any()
    model = fit_ptm(images, lights, saturation=0.6)
    np.testing.assert_allclose(model.coefficients[:, 0, 0], truth, atol=1e-4)
    assert model.report.pixels_with_missing == 4 and model.report.pixels_unfitted == 0


def test_one_nan_pixel_does_not_abort_a_masked_fit() -> None:
    normals, inside = sphere_normals(32, 32)
    lights = fibonacci_lights(20)
    images = render(normals, 0.7, lights)
    images[:, 0, 0] = np.nan  # outside the sphere: masked out
    images[4, 16, 16] = np.nan  # inside: one observation missing
    for robust in (False, True):
        result = fit_photometric_stereo(images, lights, robust=robust, mask=inside)
        assert not result.valid[0, 0]
        assert result.valid[16, 16]
        assert np.all(np.isfinite(result.normals)) and np.all(np.isfinite(result.albedo))
        # the pixel with a missing observation is fitted from the others (it is lit by all)
        one = np.zeros_like(inside)
        one[16, 16] = True
        assert _angle_deg(result.normals, normals, one) < 0.1


def test_ptm_lambertian_reading_beats_the_quadratic_maximum_on_a_glossy_sphere() -> None:
    normals, inside = sphere_normals(96, 96)
    lights = fibonacci_lights(48)
    images = render(normals, 0.6, lights, specular=0.8, shininess=60.0)
    model = fit_ptm(images, lights)
    new = _angle_deg(model.normals(), normals, inside)
    old = _angle_deg(model.normals_from_maximum(), normals, inside)
    assert new < 10.0 < 30.0 < old
