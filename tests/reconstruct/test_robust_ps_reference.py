"""The fast robust photometric stereo equals a slow, obvious per-pixel implementation.

``rti_rig.reconstruct.robust_ps`` computes the robust rules chunk by chunk, with NaN for unused
observations, a median only where the floor does not decide, downdated normal equations and a
bound instead of eigenvalues where it can. Each of those is a place to go wrong; the reference
below is the rules as the docstring of ``photometric_stereo`` states them, one pixel at a time,
in float64 with ``numpy.linalg`` (lstsq, cond). The fast path computes its residuals in float32,
so an observation lying within float32 rounding of a threshold may go either way: the tests
allow a handful of such pixels (none occur on these scenes today) and require identical kept
observations everywhere else, with normals, albedo and residual to float32 precision.
"""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.reconstruct import fit_photometric_stereo
from rti_rig.reconstruct.photometric_stereo import SHADOW_K, SHADOW_MIN_KEPT
from rti_rig.reconstruct.robust_ps import RobustRules, fit_robust_band, threshold_cut
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

DARK, FLOOR, SAT, COND = 0.02, 0.01, 1.0, 100.0


def _reference_pixel(
    obs: np.ndarray, lights: np.ndarray, shadow_k: float | None, max_passes: int = 10
) -> tuple[np.ndarray | None, np.ndarray]:
    """The rules, literally: b (or None if unsolvable) and the kept observations."""
    with np.errstate(invalid="ignore"):
        used = np.isfinite(obs) & (obs > DARK) & (obs < SAT)

    def fit(u: np.ndarray) -> np.ndarray | None:
        if u.sum() < 3 or np.linalg.cond(lights[u]) > COND:
            return None
        return np.linalg.lstsq(lights[u], obs[u], rcond=None)[0]

    def sigma(r: np.ndarray, u: np.ndarray) -> float:
        return 1.4826 * np.sort(np.abs(r[u]))[(u.sum() - 1) // 2]  # the lower median

    b = fit(used)
    if b is None:
        return None, used
    for _ in range(max_passes):  # rule 3: highlights
        r = obs - lights @ b
        drop = used & (r > max(2.0 * sigma(r, used), FLOOR))
        if not drop.any():
            break
        used = used & ~drop
        b = fit(used)
        if b is None:
            return None, used
    if shadow_k is not None:
        for _ in range(max_passes):  # rule 4: the darkest, one per pass
            if used.sum() <= SHADOW_MIN_KEPT:
                break
            r = obs - lights @ b
            j = np.flatnonzero(used)[np.argmin(r[used])]
            if not r[j] < -max(shadow_k * sigma(r, used), FLOOR):
                break
            trial = used.copy()
            trial[j] = False
            b_trial = fit(trial)
            if b_trial is None:  # a drop that leaves the pixel unsolvable is not made
                break
            used, b = trial, b_trial
    return b, used


def _reference(
    images: np.ndarray, lights: np.ndarray, mask: np.ndarray, shadow_k: float | None
) -> dict[str, np.ndarray]:
    n_img = images.shape[0]
    flat = images.reshape(n_img, -1, images.shape[3] if images.ndim == 4 else 1)
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(flat) | (flat >= SAT)
    grey = np.where(bad.any(axis=2), np.nan, flat.astype(np.float64).mean(axis=2))
    p = grey.shape[1]
    out = {
        "valid": np.zeros(p, bool),
        "used": np.zeros(p, int),
        "normals": np.tile([0.0, 0.0, 1.0], (p, 1)),
        "albedo": np.zeros((p, flat.shape[2])),
        "residual": np.zeros(p),
    }
    for i in np.flatnonzero(mask.ravel()):
        b, used = _reference_pixel(grey[:, i], lights, shadow_k)
        if b is None:
            continue
        b[2] = max(b[2], 0.0)
        if np.linalg.norm(b) <= 1e-6:
            continue
        n = b / np.linalg.norm(b)
        shade = lights[used] @ n
        out["valid"][i], out["used"][i], out["normals"][i] = True, used.sum(), n
        out["albedo"][i] = shade @ flat[used, i].astype(np.float64) / (shade @ shade)
        out["residual"][i] = np.sqrt(np.mean((lights[used] @ b - grey[used, i]) ** 2))
    return out


def _compare(fast: dict[str, np.ndarray], ref: dict[str, np.ndarray], max_flips: int) -> None:
    same = (fast["valid"] == ref["valid"]) & (fast["used"] == ref["used"])
    assert (~same).sum() <= max_flips, f"{(~same).sum()} pixels kept other observations"
    both = same & ref["valid"]
    assert both.sum() > 0.9 * ref["valid"].sum()
    # the angle between unit vectors, from their difference (arccos of a float32 dot product
    # near 1 would be resolution-limited to ~0.01°)
    angle = np.degrees(np.linalg.norm(fast["normals"][both] - ref["normals"][both], axis=1))
    # float32 sums, amplified up to the condition limit on pixels that kept few lights
    assert angle.max() < 0.01 and np.percentile(angle, 99) < 1e-3
    np.testing.assert_allclose(fast["albedo"][both], ref["albedo"][both], rtol=1e-4, atol=1e-6)
    np.testing.assert_allclose(fast["residual"][both], ref["residual"][both], rtol=1e-3, atol=2e-6)
    assert np.all(fast["used"][~fast["valid"]] == 0)
    assert np.all(fast["albedo"][~fast["valid"]] == 0)


def _fast(images: np.ndarray, lights: np.ndarray, mask: np.ndarray, shadow_k: float | None):
    res = fit_photometric_stereo(
        images,
        lights,
        robust=True,
        mask=mask,
        dark_threshold=DARK,
        saturation=SAT,
        highlight_floor=FLOOR,
        cond_limit=COND,
        shadow_k=shadow_k,
    )
    p = res.valid.size
    return {
        "valid": res.valid.ravel(),
        "used": res.used_lights.ravel().astype(int),
        "normals": res.normals.reshape(p, 3).astype(np.float64),
        "albedo": res.albedo.reshape(p, -1).astype(np.float64),
        "residual": res.residual.ravel().astype(np.float64),
    }


def _random_stack(seed: int, size: int, n: int, colour: bool = False) -> tuple[np.ndarray, ...]:
    """Random normals and albedo under random lights, then everything the rules are for:
    specular spikes and lobes, attached and partial shadows, saturation, NaN observations,
    pixels left with few usable lights, a mask."""
    rng = np.random.default_rng(seed)
    lights = rng.normal(size=(n, 3))
    lights[:, 2] = np.abs(lights[:, 2]) + 0.3
    lights /= np.linalg.norm(lights, axis=1, keepdims=True)
    normals = rng.normal(size=(size * size, 3))
    normals[:, 2] = np.abs(normals[:, 2]) + 0.5
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    albedo = rng.uniform(0.2, 0.8, size * size)
    obs = albedo * np.maximum(lights @ normals.T, 0.0)  # (n, P): attached shadows
    half = lights + np.array([0.0, 0.0, 1.0])
    half /= np.linalg.norm(half, axis=1, keepdims=True)
    obs += rng.uniform(0, 0.6, size * size) * np.maximum(half @ normals.T, 0.0) ** 30
    spikes = rng.random(obs.shape) < 0.04
    obs[spikes] += rng.uniform(0.05, 0.5, spikes.sum())
    partial = rng.random(obs.shape) < 0.05
    obs[partial] *= rng.uniform(0.2, 0.8, partial.sum())
    obs += rng.normal(0, 0.004, obs.shape)
    few = rng.random(size * size) < 0.05  # pixels that keep 2-6 usable lights
    for i in np.flatnonzero(few):
        obs[rng.permutation(n)[rng.integers(2, 7) :], i] = 0.0
    obs[rng.random(obs.shape) < 0.02] = np.nan
    obs[rng.random(obs.shape) < 0.01] = 1.5  # saturated: clipped below
    obs = np.minimum(obs, SAT + 0.25).astype(np.float32)
    images = obs.reshape(n, size, size)
    if colour:
        tint = np.array([1.0, 0.8, 0.6], dtype=np.float32)
        images = images[..., None] * tint
        images[..., 0][rng.random(images.shape[:3]) < 0.01] = SAT  # one channel saturated
    mask = rng.random((size, size)) > 0.1
    return images, lights, mask


@pytest.mark.parametrize("shadow_k", [SHADOW_K, None])
@pytest.mark.parametrize("seed", [0, 1])
def test_random_stacks_match_the_reference(seed: int, shadow_k: float | None) -> None:
    images, lights, mask = _random_stack(seed, 36, 24)
    fast = _fast(images, lights, mask, shadow_k)
    ref = _reference(images, lights, mask, shadow_k)
    assert 0.5 < ref["valid"].mean() < 0.95  # invalid pixels (few lights, mask) included
    _compare(fast, ref, max_flips=3)


def test_colour_stack_matches_the_reference() -> None:
    images, lights, mask = _random_stack(5, 24, 20, colour=True)
    fast = _fast(images, lights, mask, SHADOW_K)
    ref = _reference(images, lights, mask, SHADOW_K)
    _compare(fast, ref, max_flips=3)


def test_rendered_glossy_sphere_matches_the_reference() -> None:
    """A rendered sphere with Blinn–Phong highlights (several passes of rule 3), exposed so
    that the brightest highlights saturate, with noise."""
    lights = fibonacci_lights(40)
    normals, inside = sphere_normals(40, 40)
    images = render(normals, 0.6, lights, specular=0.8, shininess=40.0)
    images += np.random.default_rng(4).normal(0, 0.003, images.shape).astype(np.float32)
    images = np.minimum(images * np.float32(0.9), np.float32(SAT))
    assert (images >= SAT).any()
    mask = np.ones_like(inside)
    fast = _fast(images, lights, mask, SHADOW_K)
    ref = _reference(images, lights, mask, SHADOW_K)
    assert ref["valid"].mean() > 0.9
    _compare(fast, ref, max_flips=3)


def test_chunk_boundaries_do_not_change_the_fit() -> None:
    """The band is fitted chunk by chunk: any chunk size (1 pixel, a prime, the whole band)
    keeps the same observations and gives the same fit (to float32 sums: BLAS may block a
    product differently by its shape)."""
    images, lights, mask = _random_stack(2, 30, 20)
    g = images.reshape(20, -1)
    rules = RobustRules(DARK, SAT, 2.0, FLOOR, 10, COND, SHADOW_K, SHADOW_MIN_KEPT, 1e-6)
    whole = fit_robust_band(g, mask.ravel(), lights, rules, chunk=g.shape[1])
    for chunk in (1, 97):
        part = fit_robust_band(g, mask.ravel(), lights, rules, chunk=chunk)
        n_w, alb_w, rms_w, count_w, ok_w = whole
        n_p, alb_p, rms_p, count_p, ok_p = part
        np.testing.assert_array_equal(ok_w, ok_p)
        np.testing.assert_array_equal(count_w, count_p)
        np.testing.assert_allclose(n_w, n_p, atol=1e-5)
        np.testing.assert_allclose(alb_w, alb_p, rtol=1e-4, atol=1e-6)
        np.testing.assert_allclose(rms_w, rms_p, rtol=1e-3, atol=1e-6)


@pytest.mark.parametrize("scale", [2.0, 3.0, 0.5])
@pytest.mark.parametrize("floor", [0.01, 3e-5, 1.0])
def test_threshold_cut_is_where_the_median_starts_to_matter(scale: float, floor: float) -> None:
    """``threshold_cut`` is the last float32 median whose threshold is still the floor."""
    cut = threshold_cut(scale, floor)
    f = np.float32(floor)

    def thr(m: np.float32) -> np.float32:
        return np.float32(scale) * (np.float32(1.4826) * m)

    assert thr(cut) <= f
    assert thr(np.nextafter(cut, np.float32(np.inf))) > f
    assert threshold_cut(0.0, floor) > 1e38  # a zero scale: the floor for any finite median


@pytest.mark.parametrize("floor", [0.01, 0.0])
def test_thresholds_decide_exactly_as_the_sorted_median(floor: float) -> None:
    """The bracketed threshold drops exactly what the plain one drops: random residual columns
    (NaN unused), with values placed right at the plain thresholds and next to them."""
    from rti_rig.reconstruct.robust_ps import _thresholds

    rng = np.random.default_rng(7)
    n, k = 40, 3000
    sub = (rng.standard_cauchy((n, k)) * rng.uniform(0.001, 0.05, k)).astype(np.float32)
    sub[rng.random((n, k)) < 0.3] = np.nan
    counts = np.sum(~np.isnan(sub), axis=0)
    f32 = np.float32

    def plain(col: np.ndarray) -> np.float32:
        used = np.sort(np.abs(col[~np.isnan(col)]))
        med = used[(used.size - 1) // 2]
        return max(f32(2.0) * (f32(1.4826) * med), f32(floor))

    expected = np.array([plain(sub[:, j]) for j in range(k)], dtype=np.float32)
    # knife edges: some values exactly at the threshold and one float32 step either side
    for j in range(0, k, 3):
        row = rng.integers(n)
        if not np.isnan(sub[row, j]):
            step = [0.0, np.inf, -np.inf][j % 9 // 3]
            sub[row, j] = np.nextafter(expected[j], f32(step)) if step else expected[j]
    expected = np.array([plain(sub[:, j]) for j in range(k)], dtype=np.float32)
    cut = threshold_cut(2.0, floor)
    thr = _thresholds(sub, counts, 2.0, f32(floor), cut, sub)
    np.testing.assert_array_equal(sub > thr[None, :], sub > expected[None, :])
    low = np.nanmin(sub, axis=0)
    thr1 = _thresholds(sub, counts, 2.0, f32(floor), cut, -low[None, :])
    np.testing.assert_array_equal(-low > thr1, -low > expected)


def test_a_transposed_stack_fits_like_a_contiguous_one() -> None:
    """A caller's (N, H, W) stack built from a transposed array is not C-ordered; the chunked
    fit writes its working copy through flat indices, so that copy must be C-ordered anyway
    (it asserted and crashed on such input)."""
    from rti_rig.reconstruct import fit_photometric_stereo

    rng = np.random.default_rng(3)
    lights = rng.normal(size=(12, 3)) * [0.5, 0.5, 0.2]
    lights[:, 2] = np.abs(lights[:, 2]) + 0.6
    lights /= np.linalg.norm(lights, axis=1, keepdims=True)
    n = rng.normal(size=(40, 3)) * [0.3, 0.3, 1.0]
    n[:, 2] = np.abs(n[:, 2]) + 0.5
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    obs_pl = np.maximum(n @ lights.T, 0.0).astype(np.float32)  # (P, L)
    transposed = obs_pl.T[:, None, :]  # (L, 1, P), F-ordered underneath
    assert not transposed.flags.c_contiguous
    a = fit_photometric_stereo(transposed, lights, robust=True)
    b = fit_photometric_stereo(np.ascontiguousarray(transposed), lights, robust=True)
    assert np.array_equal(a.normals, b.normals) and np.array_equal(a.valid, b.valid)
