"""Light-gain calibration from a level target: recovers known gains, and dividing them out
restores photometric stereo's accuracy."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.metrics import angular_error_deg
from rti_rig.reconstruct import ReconstructionError, fit_photometric_stereo
from rti_rig.reconstruct.light_gains import apply_light_gains, estimate_light_gains
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

LIGHTS = fibonacci_lights(24, min_elevation_deg=15.0)


def _gains(n: int, seed: int = 3, spread: float = 0.25) -> np.ndarray:
    g = np.exp(np.random.default_rng(seed).normal(0.0, spread, n))
    return g / np.exp(np.median(np.log(g)))


def _card(
    h: int = 60, w: int = 80, tilt: np.ndarray | None = None, lights: np.ndarray = LIGHTS
) -> np.ndarray:
    """A level card (normal ``tilt`` or the zenith) with uneven albedo: falloff and specks."""
    rng = np.random.default_rng(5)
    yy, xx = np.mgrid[0:h, 0:w]
    albedo = 0.8 * (1.0 - 0.3 * ((xx - w / 2) ** 2 + (yy - h / 2) ** 2) / (w * w / 4))
    albedo *= 1.0 + 0.05 * rng.standard_normal((h, w))
    albedo[rng.random((h, w)) < 0.01] = 0.05  # dust
    n = np.zeros((h, w, 3))
    n[...] = [0.0, 0.0, 1.0] if tilt is None else tilt
    return render(n, albedo, lights)


def test_recovers_known_gains_of_a_level_card() -> None:
    true = _gains(len(LIGHTS))
    images = _card() * true[:, None, None].astype(np.float32)
    res = estimate_light_gains(images, LIGHTS)
    assert res.estimated.all()
    np.testing.assert_allclose(res.gains, true, rtol=2e-3)
    assert np.isclose(np.median(res.gains), 1.0)
    assert res.last_step < 1e-3


def test_robust_to_saturated_patch_and_noise() -> None:
    true = _gains(len(LIGHTS), seed=4)
    rng = np.random.default_rng(0)
    images = _card() * true[:, None, None].astype(np.float32)
    images = images * (1.0 + 0.02 * rng.standard_normal(images.shape)).astype(np.float32)
    images[:, :8, :8] = 1.0  # a clipped corner in every image
    res = estimate_light_gains(images, LIGHTS)
    np.testing.assert_allclose(res.gains, true, rtol=0.01)


def test_colour_gains_per_channel() -> None:
    grey = _card()
    true = np.stack([_gains(len(LIGHTS), s) for s in (1, 2, 3)], axis=1)
    images = grey[..., None] * true[:, None, None, :].astype(np.float32)
    res = estimate_light_gains(images, LIGHTS)
    assert res.gains.shape == (len(LIGHTS), 3)
    np.testing.assert_allclose(res.gains, true, rtol=2e-3)


def test_tilted_target_normal_is_used() -> None:
    tilt = np.array([np.sin(np.radians(20.0)), 0.0, np.cos(np.radians(20.0))])
    true = _gains(len(LIGHTS))
    images = _card(tilt=tilt) * true[:, None, None].astype(np.float32)
    right = estimate_light_gains(images, LIGHTS, target_normal=tilt)
    wrong = estimate_light_gains(images, LIGHTS)
    np.testing.assert_allclose(right.gains[right.estimated], true[right.estimated], rtol=2e-3)
    # assuming the card level when it is not gives a tilt-shaped error in the gains
    assert np.max(np.abs(wrong.gains / true - 1.0)) > 0.1


def test_grazing_light_is_left_unestimated() -> None:
    lights = np.vstack([LIGHTS, [[np.cos(np.radians(3.0)), 0.0, np.sin(np.radians(3.0))]]])
    card = np.concatenate(
        [_card(), render(np.dstack([np.zeros((60, 80, 2)), np.ones((60, 80))]), 0.8, lights[-1:])]
    )
    res = estimate_light_gains(card, lights)
    assert not res.estimated[-1] and res.estimated[:-1].all()
    assert res.gains[-1] == 1.0


def test_min_shading_lets_a_calibration_measure_low_lights() -> None:
    el = np.radians(8.0)
    lights = np.vstack([LIGHTS, [[np.cos(el), 0.0, np.sin(el)]]])
    card = _card(lights=lights)
    card[-1] *= 0.7  # the low LED is dim
    assert not estimate_light_gains(card, lights).estimated[-1]  # the default skips it
    res = estimate_light_gains(card, lights, min_shading=np.sin(np.radians(5.0)))
    assert res.estimated.all()
    ratio = res.gains[-1] / np.median(res.gains[:-1])
    assert ratio == pytest.approx(0.7, rel=0.02)
    with pytest.raises(ReconstructionError, match="min_shading must be in"):
        estimate_light_gains(card, lights, min_shading=1.5)
    with pytest.raises(ReconstructionError, match="need 4; is the card's normal right"):
        estimate_light_gains(card, lights, min_shading=0.999)


def test_dividing_gains_out_restores_photometric_stereo() -> None:
    normals, inside = sphere_normals(64, 64)
    true = _gains(len(LIGHTS), seed=7)
    scene = render(normals, 0.7, LIGHTS) * true[:, None, None].astype(np.float32)
    gains = estimate_light_gains(_card() * true[:, None, None].astype(np.float32), LIGHTS).gains
    raw = fit_photometric_stereo(scene, LIGHTS, robust=True)
    fixed = fit_photometric_stereo(apply_light_gains(scene, gains), LIGHTS, robust=True)
    err_raw = angular_error_deg(raw.normals[inside], normals[inside]).mean
    err_fixed = angular_error_deg(fixed.normals[inside], normals[inside]).mean
    assert err_raw > 3.0
    assert err_fixed < 0.05


def test_apply_does_not_modify_input_and_divides() -> None:
    images = np.ones((4, 2, 3), dtype=np.float32)
    out = apply_light_gains(images, [1.0, 2.0, 4.0, 0.5])
    assert np.all(images == 1.0)
    np.testing.assert_allclose(out[:, 0, 0], [1.0, 0.5, 0.25, 2.0])


@pytest.mark.parametrize(
    ("gains", "match"),
    [
        ([1.0, 1.0, 1.0], "3 gains for 4 images"),
        ([1.0, 0.0, 1.0, 1.0], "gain of light 1"),
        ([1.0, 1.0, np.nan, 1.0], "gain of light 2"),
        (np.ones((4, 3)), "need colour images"),
    ],
)
def test_apply_rejects_bad_gains(gains: object, match: str) -> None:
    with pytest.raises(ReconstructionError, match=match):
        apply_light_gains(np.ones((4, 2, 3), dtype=np.float32), gains)


def test_refusals() -> None:
    card = _card()
    with pytest.raises(ReconstructionError, match="at least 4 lights"):
        estimate_light_gains(card[:3], LIGHTS[:3])
    with pytest.raises(ReconstructionError, match="must pair"):
        estimate_light_gains(card[:10], LIGHTS)
    with pytest.raises(ReconstructionError, match="target are lit"):
        estimate_light_gains(np.zeros_like(card), LIGHTS)
    dead = card.copy()
    dead[5] = 0.0
    with pytest.raises(ReconstructionError, match=r"light 5 .*dead LED"):
        estimate_light_gains(dead, LIGHTS)
    nan = card.copy()
    nan[2, 0, 0] = np.nan
    with pytest.raises(ReconstructionError, match="NaN"):
        estimate_light_gains(nan, LIGHTS, max_pixels=card.shape[1] * card.shape[2])
