"""Metrics against hand-computed answers."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.metrics import (
    angular_error_deg,
    normal_map_psnr,
    normal_map_ssim,
    psnr,
    relight_psnr,
    relight_psnr_per_light,
    relight_ssim,
    ssim,
    ssim_map,
)
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct import fit_hsh, fit_photometric_stereo
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals


def _rotate_x(normals: np.ndarray, deg: float) -> np.ndarray:
    a = np.radians(deg)
    r = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    return normals @ r.T


def _tilt_by(normals: np.ndarray, deg: float) -> np.ndarray:
    """Each normal turned by exactly ``deg`` about an axis perpendicular to it."""
    t = np.cross(normals, [0.3, -0.5, 0.1])
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    a = np.radians(deg)
    return np.cos(a) * normals + np.sin(a) * t


def test_angular_error_of_a_known_rotation() -> None:
    n, _ = sphere_normals(20, 20)
    stats = angular_error_deg(_tilt_by(n, 7.5), n)
    assert stats.mean == pytest.approx(7.5, abs=1e-9)
    assert stats.median == pytest.approx(7.5, abs=1e-9)
    assert stats.p90 == pytest.approx(7.5, abs=1e-9)
    assert stats.count == 400


def test_angular_error_tiny_angles_and_mask() -> None:
    n = np.zeros((2, 2, 3))
    n[..., 2] = 1.0
    est = n.copy()
    est[0, 0] = direction_from_az_el(0.0, 90.0 - 1e-6)
    est[1, 1] = [1.0, 0.0, 0.0]
    mask = np.array([[True, True], [True, False]])
    stats = angular_error_deg(est, n, mask)
    assert stats.count == 3
    assert stats.mean == pytest.approx(1e-6 / 3, rel=1e-6)
    assert angular_error_deg(est, n).p90 > 60
    est[0, 1] = 0.0
    with pytest.raises(ValueError, match="zero length"):
        angular_error_deg(est, n)


def test_psnr_of_a_constant_offset() -> None:
    ref = np.random.default_rng(0).uniform(0, 1, (16, 16, 3))
    assert psnr(ref + 0.01, ref, 1.0) == pytest.approx(40.0)
    assert psnr(ref + 0.01, ref, 2.0) == pytest.approx(40.0 + 20 * np.log10(2))
    assert psnr(ref, ref, 1.0) == 100.0


def _brute_ssim_at(a: np.ndarray, b: np.ndarray, r: int, c: int, data_range: float) -> float:
    """Wang et al. 2004 at one pixel, with an explicit normalised 11 × 11 Gaussian window."""
    k = np.arange(-5, 6)
    g = np.exp(-(k[:, None] ** 2 + k[None, :] ** 2) / (2 * 1.5**2))
    g /= g.sum()
    pa, pb = a[r - 5 : r + 6, c - 5 : c + 6], b[r - 5 : r + 6, c - 5 : c + 6]
    ma, mb = (g * pa).sum(), (g * pb).sum()
    va, vb = (g * (pa - ma) ** 2).sum(), (g * (pb - mb) ** 2).sum()
    cov = (g * (pa - ma) * (pb - mb)).sum()
    c1, c2 = (0.01 * data_range) ** 2, (0.03 * data_range) ** 2
    return ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma**2 + mb**2 + c1) * (va + vb + c2))


def test_ssim_matches_the_definition() -> None:
    rng = np.random.default_rng(1)
    a = rng.uniform(0, 1, (30, 30))
    b = np.clip(a + rng.normal(0, 0.1, a.shape), 0, 1)
    m = ssim_map(a, b, 1.0)
    for r, c in ((10, 12), (15, 15), (20, 8)):
        assert m[r, c] == pytest.approx(_brute_ssim_at(a, b, r, c, 1.0), abs=1e-10)
    assert ssim(a, a, 1.0) == pytest.approx(1.0)
    assert ssim(a, b, 1.0) == pytest.approx(ssim(b, a, 1.0))
    worse = np.clip(a + rng.normal(0, 0.3, a.shape), 0, 1)
    assert ssim(a, worse, 1.0) < ssim(a, b, 1.0) < 1.0


def test_ssim_rejects_tiny_images_and_empty_masks() -> None:
    with pytest.raises(ValueError, match="larger"):
        ssim(np.zeros((8, 8)), np.zeros((8, 8)), 1.0)
    mask = np.zeros((20, 20), dtype=bool)
    mask[:3] = True
    with pytest.raises(ValueError, match="border"):
        ssim(np.zeros((20, 20)), np.zeros((20, 20)), 1.0, mask)


def test_normal_map_psnr_uses_encoded_range_one() -> None:
    n, _ = sphere_normals(24, 24)
    est = n.copy()
    est[..., 0] += 0.02  # encoded offset 0.01 in one of three channels
    expected = 10 * np.log10(1.0 / (0.01**2 / 3))
    assert normal_map_psnr(est, n) == pytest.approx(expected)
    assert normal_map_ssim(n, n) == pytest.approx(1.0)
    assert normal_map_ssim(_rotate_x(n, 20), n) < normal_map_ssim(_rotate_x(n, 5), n) < 1.0


def test_relighting_metrics_on_held_out_lights() -> None:
    normals, _ = sphere_normals(32, 32)
    lights = fibonacci_lights(45)
    images = render(normals, 0.8, lights)
    train, test = np.arange(45) % 5 != 0, np.arange(45) % 5 == 0
    hsh = fit_hsh(images[train], lights[train], 2)
    per = relight_psnr_per_light(hsh, images[test], lights[test])
    manual = psnr(hsh.relight(lights[test][0]), images[test][0], 1.0)
    assert per[0] == pytest.approx(manual)
    assert relight_psnr(hsh, images[test], lights[test]) == pytest.approx(per.mean())
    ps = fit_photometric_stereo(images[train], lights[train], robust=True)
    assert relight_psnr(ps, images[test], lights[test]) > 60  # the scene is Lambertian
    assert relight_psnr(ps, images[test], lights[test]) > relight_psnr(
        hsh, images[test], lights[test]
    )
    assert (
        0.5
        < relight_ssim(hsh, images[test], lights[test])
        < relight_ssim(ps, images[test], lights[test])
    )


def test_score_reconstruction_applies_each_metric_where_it_can() -> None:
    from benchmarks.metrics import score_reconstruction
    from rti_rig.reconstruct import fit_model

    normals, inside = sphere_normals(40, 40)
    lights = fibonacci_lights(40)
    images = render(normals, 0.7, lights)
    train, test = np.arange(40) % 4 != 0, np.arange(40) % 4 == 0
    scores = {}
    for name in ("ps-robust", "lambert", "ptm", "hsh2"):
        model = fit_model(name, images[train], lights[train])
        scores[name] = score_reconstruction(
            model,
            true_normals=normals,
            mask=inside,
            held_images=images[test],
            held_lights=lights[test],
        )
    ps = scores["ps-robust"]
    assert ps.model == "lambert-ps-robust" and ps.n_coefficients == 3
    assert ps.angular is not None and ps.angular.mean < 0.1
    assert ps.valid_fraction is not None and ps.valid_fraction > 0.99
    assert ps.normal_psnr is not None and ps.normal_psnr > 50
    # the unshadowed least-squares Lambert fit is biased by attached shadows
    assert scores["lambert"].angular.mean > 5 * ps.angular.mean
    assert scores["hsh2"].angular is None and scores["hsh2"].normal_psnr is None
    assert scores["hsh2"].relight_psnr > scores["lambert"].relight_psnr
    assert ps.relight_psnr == pytest.approx(
        relight_psnr(
            fit_photometric_stereo(images[train], lights[train], robust=True),
            images[test],
            lights[test],
            1.0,
            inside,
        )
    )
