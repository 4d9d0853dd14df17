"""PTM, HSH and Lambert relighting models: known coefficients, guards, extremes."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct import (
    ReconstructionError,
    RelightModel,
    design_matrix,
    fit_hsh,
    fit_lambert,
    fit_model,
    fit_ptm,
    hsh_basis,
    ptm_basis,
)
from rti_rig.reconstruct.synthetic import fibonacci_lights

P = {"lambert": 3, "hsh1": 4, "ptm": 6, "hsh2": 9, "hsh3": 16}


def _images_from_coefficients(model: str, coef: np.ndarray, lights: np.ndarray) -> np.ndarray:
    a = design_matrix(model, lights)
    return np.tensordot(a, coef, axes=(1, 0)).astype(np.float32)


def _positive_coefficients(model: str, shape: tuple[int, ...], seed: int = 0) -> np.ndarray:
    """Random coefficients whose images stay positive: a large constant term, small others."""
    rng = np.random.default_rng(seed)
    coef = rng.normal(0, 0.05, (P[model], *shape))
    const = {"lambert": 2, "hsh1": 0, "ptm": 5, "hsh2": 0, "hsh3": 0}[model]
    coef[const] += 3.0
    return coef


def test_hsh_basis_is_orthonormal_over_the_hemisphere() -> None:
    nt, nphi = 300, 600
    th = (np.arange(nt) + 0.5) / nt * np.pi / 2
    ph = (np.arange(nphi) + 0.5) / nphi * 2 * np.pi
    t, p = np.meshgrid(th, ph, indexing="ij")
    dirs = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1).reshape(-1, 3)
    weight = (np.sin(t) * (np.pi / 2 / nt) * (2 * np.pi / nphi)).ravel()
    a = hsh_basis(dirs, 3)
    gram = (a * weight[:, None]).T @ a
    np.testing.assert_allclose(gram, np.eye(16), atol=5e-4)


def test_hsh_order3_uses_exponent_one_and_a_half() -> None:
    d = direction_from_az_el(20.0, 40.0)
    c, phi = d[2], np.arctan2(d[1], d[0])
    expected = 2 * np.sqrt(35 / np.pi) * np.cos(3 * phi) * (c - c * c) ** 1.5
    assert hsh_basis(d[None], 3)[0, 9] == pytest.approx(expected, rel=1e-12)
    assert abs(expected - 2 * np.sqrt(35 / np.pi) * np.cos(3 * phi) * (c - c * c)) > 0.05


def test_ptm_basis_is_malzbender_order() -> None:
    a = ptm_basis(np.array([[0.3, -0.4, np.sqrt(0.75)]]))[0]
    np.testing.assert_allclose(a, [0.09, 0.16, -0.12, 0.3, -0.4, 1.0])


@pytest.mark.parametrize("model", ["lambert", "hsh1", "ptm", "hsh2", "hsh3"])
@pytest.mark.parametrize("extra", [0, 20])
def test_known_coefficients_recovered(model: str, extra: int) -> None:
    """N = p (exactly determined) and N = p + 20 both recover the generating coefficients."""
    lights = fibonacci_lights(P[model] + extra)
    coef = _positive_coefficients(model, (5, 7))
    images = _images_from_coefficients(model, coef, lights)
    fitted = fit_model(model, images, lights)
    assert isinstance(fitted, RelightModel)
    assert fitted.n_coefficients == P[model]
    assert not fitted.report.regularised
    np.testing.assert_allclose(fitted.coefficients, coef, atol=2e-4)
    new = direction_from_az_el(123.0, 37.0)
    expected = _images_from_coefficients(model, coef, new[None])[0]
    np.testing.assert_allclose(fitted.relight(new), np.maximum(expected, 0), atol=2e-4)


def test_colour_coefficients_keep_channel_axis() -> None:
    lights = fibonacci_lights(30)
    coef = _positive_coefficients("hsh2", (4, 6, 3))
    images = _images_from_coefficients("hsh2", coef, lights)
    model = fit_hsh(images, lights, 2)
    assert model.coefficients.shape == (9, 4, 6, 3)
    assert model.relight([0.0, 0.0, 1.0]).shape == (4, 6, 3)
    np.testing.assert_allclose(model.coefficients, coef, atol=2e-4)


@pytest.mark.parametrize("model", ["hsh1", "ptm", "hsh2", "hsh3"])
def test_too_few_lights_refused(model: str) -> None:
    lights = fibonacci_lights(P[model] - 1)
    images = np.ones((len(lights), 3, 3), dtype=np.float32)
    with pytest.raises(ReconstructionError, match=f"at least {P[model]} lights"):
        fit_model(model, images, lights)


def test_hsh_order_must_be_1_to_3() -> None:
    lights = fibonacci_lights(30)
    with pytest.raises(ReconstructionError, match="order"):
        fit_hsh(np.ones((30, 2, 2), dtype=np.float32), lights, 4)


def test_single_ring_is_singular_for_ptm_regularised_and_reported() -> None:
    """On one ring l_u^2 + l_v^2 is constant: PTM cannot separate a0 + a1 from a5."""
    ring = direction_from_az_el(np.arange(12) * 30.0, np.full(12, 40.0))
    coef = _positive_coefficients("ptm", (3, 4))
    images = _images_from_coefficients("ptm", coef, ring)
    with pytest.raises(ReconstructionError, match="ill-conditioned for ptm"):
        fit_ptm(images, ring, ill_conditioned="refuse")
    model = fit_ptm(images, ring)
    assert model.report.regularised
    assert model.report.condition_number > 1e6
    assert "ridge-regularised" in model.report.describe()
    assert np.all(np.isfinite(model.coefficients))
    # The regularised fit still reproduces the lights it saw, and stays bounded elsewhere.
    for i in (0, 5):
        np.testing.assert_allclose(model.relight(ring[i]), images[i], rtol=1e-3)
    assert np.abs(model.coefficients).max() < 10 * np.abs(coef).max()


def test_well_spread_lights_not_regularised() -> None:
    for model in ("hsh1", "ptm", "hsh2", "hsh3"):
        fitted = fit_model(model, np.ones((P[model], 2, 2), np.float32), fibonacci_lights(P[model]))
        assert not fitted.report.regularised, fitted.report.describe()
        assert fitted.report.condition_number < 20


def test_coplanar_lights_refused_for_lambert() -> None:
    lights = direction_from_az_el([10.0, 10.0, 10.0, 190.0], [20.0, 50.0, 80.0, 40.0])
    with pytest.raises(ReconstructionError, match="ill-conditioned"):
        fit_lambert(np.ones((4, 2, 2), np.float32), lights)


@pytest.mark.parametrize("model", ["lambert", "hsh1", "ptm", "hsh2", "hsh3"])
def test_all_dark_pixels_give_zero_coefficients(model: str) -> None:
    lights = fibonacci_lights(P[model] + 3)
    images = np.zeros((len(lights), 4, 5), dtype=np.float32)
    fitted = fit_model(model, images, lights)
    assert np.all(fitted.coefficients == 0)
    assert np.all(fitted.relight([0.3, 0.2, 0.9327379]) == 0)


def test_ptm_normals_from_the_maximum() -> None:
    """I = 1 - (u - u0)^2 - (v - v0)^2 peaks at the projection (u0, v0) of the normal."""
    u0, v0 = 0.3, -0.2
    coef = np.array([-1.0, -1.0, 0.0, 2 * u0, 2 * v0, 1.0 - u0 * u0 - v0 * v0])
    lights = fibonacci_lights(25)
    images = _images_from_coefficients("ptm", coef[:, None, None] * np.ones((6, 2, 3)), lights)
    normals = fit_ptm(images, lights).normals_from_maximum()
    expected = [u0, v0, np.sqrt(1 - u0 * u0 - v0 * v0)]
    np.testing.assert_allclose(normals, np.broadcast_to(expected, (2, 3, 3)), atol=1e-4)


def test_relight_validates_direction() -> None:
    lights = fibonacci_lights(10)
    model = fit_ptm(np.ones((10, 2, 2), np.float32), lights)
    with pytest.raises(ReconstructionError, match="below the object plane"):
        model.relight([0.0, 0.6, -0.8])
    with pytest.raises(ReconstructionError, match="unit vectors"):
        model.relight([0.0, 0.0, 2.0])


@pytest.mark.parametrize("model", ["hsh1", "ptm", "hsh2", "hsh3"])
def test_lights_on_one_ring_are_ill_conditioned_for_every_basis(model: str) -> None:
    ring = direction_from_az_el(np.arange(24) * 15.0, np.full(24, 45.0))
    images = np.ones((24, 3, 3), dtype=np.float32)
    with pytest.raises(ReconstructionError, match=f"ill-conditioned for {model}"):
        fit_model(model, images, ring, ill_conditioned="refuse")
    fitted = fit_model(model, images, ring)
    assert fitted.report.regularised
    np.testing.assert_allclose(fitted.relight(ring[3]), 1.0, rtol=1e-3)


def test_lambert_model_normals_match_photometric_stereo_without_shadows() -> None:
    from rti_rig.reconstruct import fit_photometric_stereo

    rng = np.random.default_rng(3)
    normals = rng.normal(size=(6, 5, 3)) * [0.2, 0.2, 0.0] + [0.0, 0.0, 1.0]
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    lights = direction_from_az_el(np.arange(9) * 40.0, np.full(9, 75.0))
    images = np.einsum("hwk,nk->nhw", normals, lights).astype(np.float32) * 0.5
    images[:, 0, 0] = 0.0
    model = fit_lambert(images, lights)
    got = model.normals()
    np.testing.assert_allclose(got[1:], normals[1:], atol=1e-5)
    np.testing.assert_array_equal(got[0, 0], [0.0, 0.0, 1.0])
    ps = fit_photometric_stereo(images, lights)
    np.testing.assert_allclose(got[ps.valid], ps.normals[ps.valid], atol=1e-5)
