"""Photometric stereo on synthetic scenes with known normals and albedo."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.metrics import angular_error_deg
from rti_rig.core.devices import Frame
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct import (
    ReconstructionError,
    fit_photometric_stereo,
    stack_from_frames,
)
from rti_rig.reconstruct.photometric_stereo import SHADOW_K
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals


def _gentle_normals(h: int = 24, w: int = 20, max_tilt_deg: float = 25.0) -> np.ndarray:
    """Normals tilted at most ``max_tilt_deg``: lit by every light above 70° elevation."""
    rng = np.random.default_rng(1)
    tilt = np.radians(rng.uniform(0, max_tilt_deg, (h, w)))
    az = rng.uniform(0, 2 * np.pi, (h, w))
    return np.stack([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), np.cos(tilt)], -1)


def _high_lights(n: int) -> np.ndarray:
    return direction_from_az_el(np.arange(n) * 360.0 / n + 7.0, np.full(n, 70.0))


def test_least_squares_is_exact_without_shadows() -> None:
    n_true = _gentle_normals()
    albedo = np.random.default_rng(2).uniform(0.2, 0.9, n_true.shape[:2])
    lights = _high_lights(8)
    res = fit_photometric_stereo(render(n_true, albedo, lights), lights)
    assert res.valid.all()
    assert angular_error_deg(res.normals, n_true).p90 < 0.01
    np.testing.assert_allclose(res.albedo, albedo, rtol=1e-4)
    assert np.all(res.used_lights == 8)
    assert res.residual.max() < 1e-5


def test_exactly_three_lights_recover_normals() -> None:
    n_true = _gentle_normals()
    lights = direction_from_az_el([0.0, 120.0, 240.0], [54.74, 54.74, 54.74])
    images = render(n_true, 0.5, lights)
    for robust in (False, True):
        res = fit_photometric_stereo(images, lights, robust=robust)
        assert res.valid.all()
        assert angular_error_deg(res.normals, n_true).mean < 0.01
        assert np.all(res.used_lights == 3)


def test_robust_discards_attached_shadows_where_least_squares_is_biased() -> None:
    n_true, inside = sphere_normals(64, 64)
    lights = fibonacci_lights(40)
    images = render(n_true, 0.7, lights)
    ls = fit_photometric_stereo(images, lights)
    rb = fit_photometric_stereo(images, lights, robust=True)
    assert angular_error_deg(ls.normals, n_true, inside).mean > 3.0
    err = angular_error_deg(rb.normals, n_true, inside & rb.valid)
    assert err.p90 < 0.05
    assert rb.valid[inside].mean() > 0.99
    assert rb.used_lights[inside].min() < 40  # shadowed observations really were dropped


def test_robust_discards_highlights_under_noise() -> None:
    n_true, inside = sphere_normals(64, 64)
    lights = fibonacci_lights(48)
    images = render(n_true, 0.6, lights, specular=1.5, shininess=40.0)
    images += np.random.default_rng(3).normal(0, 0.004, images.shape).astype(np.float32)
    ls = angular_error_deg(fit_photometric_stereo(images, lights).normals, n_true, inside)
    res = fit_photometric_stereo(images, lights, robust=True)
    rb = angular_error_deg(res.normals, n_true, inside & res.valid)
    assert ls.mean > 5.0
    assert rb.mean < 1.0
    assert rb.mean < ls.mean / 4


def test_pixel_with_fewer_than_three_lit_lights_is_invalid() -> None:
    n_true = np.zeros((4, 4, 3))
    n_true[...] = direction_from_az_el(45.0, 10.0)  # tilted 80° towards +x+y: 2 lights lit
    n_true[0, 0] = [0.0, 0.0, 1.0]
    lights = direction_from_az_el([0.0, 90.0, 180.0, 270.0], [30.0] * 4)
    images = render(n_true, 0.8, lights)
    res = fit_photometric_stereo(images, lights, robust=True)
    assert res.valid[0, 0]
    assert not res.valid[1:, :].any() and not res.valid[0, 1:].any()
    assert np.all(res.used_lights[~res.valid] == 0)
    assert np.all(res.albedo[~res.valid] == 0)


def test_all_dark_pixels_are_invalid_without_nan() -> None:
    n_true = _gentle_normals(10, 10)
    lights = _high_lights(6)
    images = render(n_true, 0.5, lights)
    images[:, 2:5, 3:6] = 0.0
    for robust in (False, True):
        res = fit_photometric_stereo(images, lights, robust=robust)
        assert not res.valid[2:5, 3:6].any()
        assert res.valid.sum() == 100 - 9
        for arr in (res.normals, res.albedo, res.residual):
            assert np.all(np.isfinite(arr))
        np.testing.assert_array_equal(res.normals[2:5, 3:6], np.broadcast_to([0, 0, 1], (3, 3, 3)))
        assert np.all(res.relight([0.0, 0.0, 1.0])[2:5, 3:6] == 0)


def test_coplanar_lights_are_refused() -> None:
    lights = direction_from_az_el([0.0, 0.0, 0.0, 180.0, 180.0], [20.0, 50.0, 80.0, 40.0, 70.0])
    images = np.ones((5, 4, 4), dtype=np.float32)
    with pytest.raises(ReconstructionError, match="ill-conditioned"):
        fit_photometric_stereo(images, lights)


def test_too_few_lights_are_refused() -> None:
    lights = direction_from_az_el([0.0, 90.0], [45.0, 45.0])
    with pytest.raises(ReconstructionError, match="at least 3"):
        fit_photometric_stereo(np.ones((2, 3, 3), dtype=np.float32), lights)


def test_images_and_lights_must_pair() -> None:
    with pytest.raises(ReconstructionError, match="pair one to one"):
        fit_photometric_stereo(np.ones((4, 3, 3), dtype=np.float32), _high_lights(5))
    bad = _high_lights(4)
    bad[2] = [0.6, 0.0, -0.8]
    with pytest.raises(ReconstructionError, match="light 2"):
        fit_photometric_stereo(np.ones((4, 3, 3), dtype=np.float32), bad)


def test_mask_excludes_pixels() -> None:
    n_true = _gentle_normals(8, 8)
    lights = _high_lights(6)
    mask = np.zeros((8, 8), dtype=bool)
    mask[2:6, 2:6] = True
    res = fit_photometric_stereo(render(n_true, 0.5, lights), lights, mask=mask)
    np.testing.assert_array_equal(res.valid, mask)


def test_colour_albedo_per_channel_and_relight() -> None:
    n_true = _gentle_normals(12, 10)
    albedo = np.broadcast_to(np.array([0.8, 0.5, 0.2]), (12, 10, 3))
    lights = _high_lights(7)
    images = render(n_true, albedo, lights)
    res = fit_photometric_stereo(images, lights, robust=True)
    assert res.albedo.shape == (12, 10, 3)
    np.testing.assert_allclose(res.albedo, albedo, rtol=1e-4)
    new = direction_from_az_el(33.0, 75.0)
    expected = render(n_true, albedo, new[None, :])[0]
    np.testing.assert_allclose(res.relight(new), expected, atol=1e-5)


def test_normals_unit_with_non_negative_z() -> None:
    rng = np.random.default_rng(5)
    images = rng.uniform(0, 1, (10, 16, 16)).astype(np.float32)  # arbitrary, non-Lambertian
    res = fit_photometric_stereo(images, fibonacci_lights(10), robust=True)
    assert np.all(res.normals[..., 2] >= 0)
    np.testing.assert_allclose(np.linalg.norm(res.normals, axis=-1), 1.0, atol=1e-5)


def test_saturated_frames_are_discarded() -> None:
    n_true, inside = sphere_normals(40, 40)
    lights = fibonacci_lights(30)
    images = render(n_true, 1.4, lights)  # over-exposed: brightly lit observations clip
    white = 4000
    pixels = np.clip(np.round(images * white), 0, white).astype(np.uint16)
    assert (pixels == white).mean() > 0.05
    frames = [Frame(p, 0.01, 1.0, white, 0.0) for p in pixels]
    stack = stack_from_frames(frames)
    res = fit_photometric_stereo(stack, lights, robust=True)
    assert res.saturation == 1.0
    good = angular_error_deg(res.normals, n_true, inside & res.valid)
    blind = fit_photometric_stereo(stack, lights, robust=True, saturation=float("inf"))
    bad = angular_error_deg(blind.normals, n_true, inside & blind.valid)
    assert good.mean < 0.2
    assert bad.mean > 3 * good.mean


@pytest.mark.parametrize("robust", [False, True])
def test_tiled_equals_untiled(robust: bool) -> None:
    n_true, _ = sphere_normals(37, 29)
    lights = fibonacci_lights(20)
    images = render(n_true, 0.6, lights, specular=0.8)
    whole = fit_photometric_stereo(images, lights, robust=robust, tile_rows=1000)
    tiled = fit_photometric_stereo(images, lights, robust=robust, tile_rows=4)
    np.testing.assert_array_equal(whole.valid, tiled.valid)
    np.testing.assert_array_equal(whole.used_lights, tiled.used_lights)
    np.testing.assert_allclose(whole.normals, tiled.normals, atol=1e-6)
    np.testing.assert_allclose(whole.albedo, tiled.albedo, atol=1e-6)


def test_pixel_whose_lit_lights_are_coplanar_is_invalid() -> None:
    """Globally fine lights, but for this normal only the four lights in the xz plane are lit."""
    lights = direction_from_az_el([0.0, 0.0, 0.0, 180.0, 90.0], [30.0, 60.0, 90.0, 45.0, 10.0])
    normals = np.empty((2, 2, 3))
    normals[...] = direction_from_az_el(270.0, 60.0)  # shadows the az-90 light
    normals[0, 0] = [0.0, 0.0, 1.0]  # sees all five
    images = render(normals, 0.5, lights)
    res = fit_photometric_stereo(images, lights, robust=True)
    assert res.valid[0, 0]
    assert res.valid.sum() == 1
    assert res.used_lights[0, 0] == 5
    ls = fit_photometric_stereo(images, lights)
    assert ls.valid.all()  # least squares uses the shadowed zero and returns a biased normal
    assert angular_error_deg(ls.normals, normals, ~np.eye(2, dtype=bool)).mean > 1.0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_robust_drops_partial_shadows_but_keeps_five(seed: int) -> None:
    """A pixel on a cast shadow's edge (or under a weak LED) is darker than Lambert says yet
    too bright to count as shadow: rule 4 drops it, where the fit without it is tilted."""
    rng = np.random.default_rng(seed)
    n_true = _gentle_normals(12, 10, 20.0)
    lights = _high_lights(12)
    images = render(n_true, 0.6, lights) + rng.normal(0, 0.002, (12, 12, 10)).astype(np.float32)
    images[3] *= 0.55  # one light half-shadowed on every pixel
    images[8, :6] *= 0.7  # another on half of them
    on = fit_photometric_stereo(images, lights, robust=True)  # the rule is on by default
    off = fit_photometric_stereo(images, lights, robust=True, shadow_k=None)
    assert angular_error_deg(off.normals, n_true).mean > 3.0
    assert angular_error_deg(on.normals, n_true).p90 < 0.6
    # both dark observations go where there are two, the one elsewhere; noise rarely costs more
    assert on.used_lights[:6].max() == 10 and on.used_lights[6:].max() == 11
    assert np.mean(on.used_lights[6:] == 11) > 0.7 and on.used_lights.min() >= 9
    # never fewer than five observations: with six lights, at most one dark one goes
    dark = images[:6].copy()
    dark[[1, 4]] *= 0.3
    six = fit_photometric_stereo(dark, lights[:6], robust=True, shadow_k=SHADOW_K)
    assert six.used_lights.min() == 5 and six.valid.all()
    five = fit_photometric_stereo(images[:5], lights[:5], robust=True, shadow_k=SHADOW_K)
    assert np.all(five.used_lights == 5)


def test_partial_shadow_rule_leaves_clean_noisy_data_alone() -> None:
    """Under plain sensor noise the darkest residual rarely exceeds 3 robust sigmas."""
    n_true = _gentle_normals(40, 40, 25.0)
    lights = _high_lights(24)
    images = render(n_true, 0.6, lights)
    images += np.random.default_rng(5).normal(0, 0.003, images.shape).astype(np.float32)
    res = fit_photometric_stereo(images, lights, robust=True, shadow_k=SHADOW_K)
    off = fit_photometric_stereo(images, lights, robust=True, shadow_k=None)
    assert np.mean(res.used_lights < off.used_lights) < 0.1
    on_err = angular_error_deg(res.normals, n_true).mean
    assert on_err < 1.05 * angular_error_deg(off.normals, n_true).mean


def test_partial_shadow_rule_options_are_checked() -> None:
    lights = _high_lights(8)
    images = render(_gentle_normals(4, 4), 0.5, lights)
    # least squares discards nothing: shadow_k is the robust fit's alone
    plain = fit_photometric_stereo(images, lights, shadow_k=None)
    default_ls = fit_photometric_stereo(images, lights)
    assert np.array_equal(default_ls.normals, plain.normals)
    assert default_ls.shadow_k is None  # the result records the rule it applied
    assert fit_photometric_stereo(images, lights, robust=True).shadow_k == SHADOW_K
    assert fit_photometric_stereo(images, lights, robust=True, shadow_k=None).shadow_k is None
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ReconstructionError, match="positive"):
            fit_photometric_stereo(images, lights, robust=True, shadow_k=bad)
