"""The fast robust photometric stereo equals a slow, obvious per-pixel implementation.

``rti_rig.reconstruct.robust_kernel`` computes the robust rules in compiled per-pixel loops,
with NaN for unused observations, thresholds judged by counts instead of medians, downdated
normal equations and a bound instead of eigenvalues where it can. Each of those is a place to
go wrong; the reference below is the rules as the docstring of ``photometric_stereo`` states
them, one pixel at a time, in float64 with ``numpy.linalg`` (lstsq, cond). The fast path
computes its residuals in float32, so an observation lying within float32 rounding of a
threshold may go either way: the tests allow a handful of such pixels on the random scenes
(none occur today) and require identical kept observations everywhere else, with normals,
albedo and residual to float32 precision.
"""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.reconstruct import fit_photometric_stereo
from rti_rig.reconstruct.errors import IllConditionedFitWarning
from rti_rig.reconstruct.photometric_stereo import SHADOW_K, SHADOW_MIN_KEPT
from rti_rig.reconstruct.robust_ps import RobustRules, fit_robust_band
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals

DARK, FLOOR, SAT, COND = 0.02, 0.01, 1.0, 100.0


def _reference_pixel(
    obs: np.ndarray,
    lights: np.ndarray,
    shadow_k: float | None,
    max_passes: int = 10,
    events: list[str] | None = None,
) -> tuple[np.ndarray | None, np.ndarray]:
    """The rules, literally: b (or None if unsolvable) and the kept observations; ``events``
    collects the rare branches taken (for tests that must reach them)."""
    events = [] if events is None else events
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
            events.append("highlight drop left it unsolvable")
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
                events.append("partial-shadow drop refused")
                break
            used, b = trial, b_trial
    return b, used


def _reference(
    images: np.ndarray,
    lights: np.ndarray,
    mask: np.ndarray,
    shadow_k: float | None,
    events: list[str] | None = None,
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
        b, used = _reference_pixel(grey[:, i], lights, shadow_k, events=events)
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


def _random_stack(
    seed: int, size: int, n: int, colour: bool = False, noise: float = 0.004
) -> tuple[np.ndarray, ...]:
    """Random normals and albedo under random lights, then everything the rules are for:
    specular spikes and lobes, attached and partial shadows, saturation, NaN observations,
    pixels left with few usable lights, a mask; Gaussian noise of sigma ``noise`` (above
    the floor's scale, the thresholds come from the medians rather than the floor)."""
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
    obs += rng.normal(0, noise, obs.shape)
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


@pytest.mark.parametrize("n", [13, 70])
def test_light_counts_off_the_kernels_simd_and_bit_words_match_the_reference(n: int) -> None:
    """The kernel compares 8 residuals at a time (padded with NaN) and keeps the candidates
    above the floor as bits of 64-light words: a count that is no multiple of 8, and one
    beyond a word (with highlights and partial shadows on lights past the 64th)."""
    for noise in (0.004, 0.02):
        images, lights, mask = _random_stack(6 + n, 20, n, noise=noise)
        fast = _fast(images, lights, mask, SHADOW_K)
        ref = _reference(images, lights, mask, SHADOW_K)
        assert ref["valid"].mean() > 0.5
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


def test_any_split_of_the_band_gives_the_same_fit_bit_for_bit() -> None:
    """The kernel takes pixels in blocks (BLOCK_PIXELS) and each pixel on its own: a band, its
    pixels one at a time and its slices of a prime length give identical outputs."""
    from rti_rig.reconstruct.robust_kernel import BLOCK_PIXELS

    images, lights, mask = _random_stack(2, 30, 20)
    g = images.reshape(20, -1)
    inside = mask.ravel()
    assert g.shape[1] > 2 * BLOCK_PIXELS
    rules = RobustRules(DARK, SAT, 2.0, FLOOR, 10, COND, SHADOW_K, SHADOW_MIN_KEPT, 1e-6)
    whole = fit_robust_band(g, inside, lights, rules)
    for step in (1, 97):
        parts = [
            fit_robust_band(g[:, s : s + step], inside[s : s + step], lights, rules)
            for s in range(0, g.shape[1], step)
        ]
        for w, p in zip(whole, zip(*parts, strict=True), strict=True):
            np.testing.assert_array_equal(w, np.concatenate(p))


@pytest.mark.parametrize("n", [40, 37])
@pytest.mark.parametrize("scale", [2.0, 3.0])
@pytest.mark.parametrize("floor", [0.01, 0.0])
def test_a_residual_exceeds_the_threshold_exactly_as_with_the_sorted_median(
    scale: float, floor: float, n: int
) -> None:
    """The kernel never computes a median: a residual exceeds the threshold iff more than half
    of the used |residuals|, each mapped to the threshold it would set, are below it. Random
    columns (NaN unused), with values placed right at the plain thresholds and one float32
    step either side; ``n`` a multiple of the kernel's 8 SIMD lanes, or not (a scalar
    tail)."""
    from rti_rig.reconstruct.robust_kernel import _exceeds, _scales

    rng = np.random.default_rng(7)
    k = 1500
    sub = (rng.standard_cauchy((n, k)) * rng.uniform(0.001, 0.05, k)).astype(np.float32)
    sub[rng.random((n, k)) < 0.3] = np.nan
    f32 = np.float32

    def plain(col: np.ndarray) -> np.float32:
        used = np.sort(np.abs(col[~np.isnan(col)]))
        med = used[(used.size - 1) // 2]
        return max(f32(scale) * (f32(1.4826) * med), f32(floor))

    expected = np.array([plain(sub[:, j]) for j in range(k)], dtype=np.float32)
    for j in range(0, k, 3):  # knife edges: a value at the threshold and a step either side
        row = rng.integers(n)
        if not np.isnan(sub[row, j]):
            step = [0.0, np.inf, -np.inf][j % 9 // 3]
            sub[row, j] = np.nextafter(expected[j], f32(step)) if step else expected[j]
    expected = np.array([plain(sub[:, j]) for j in range(k)], dtype=np.float32)
    sc = np.empty(n, dtype=np.float32)
    edges = 0
    for j in range(k):
        col = sub[:, j]
        used = int((~np.isnan(col)).sum())
        _scales(col, f32(scale), f32(1.4826), sc)
        for x in col[~np.isnan(col)]:
            assert _exceeds(x, sc, used, f32(floor)) == (x > expected[j])
            edges += x == expected[j]
        low = np.nanmin(col)
        assert _exceeds(-low, sc, used, f32(floor)) == (-low > expected[j])
    assert edges > 20  # values exactly at a threshold were judged


def test_edge_cases_match_the_reference() -> None:
    """Pixels built to hit each edge: every observation unused (dark, NaN, +inf, -inf,
    saturated, outside the mask), fewer than 3 usable, exactly 3, NaN and infinite values
    among good ones, a pixel whose highlights all saturate; fitted as one band."""
    lights = fibonacci_lights(16)
    normal = np.array([0.2, -0.1, 0.97])
    normal /= np.linalg.norm(normal)
    clean = (0.6 * np.maximum(lights @ normal, 0.0)).astype(np.float32)
    cols = {}
    cols["all dark"] = np.full(16, 0.001, np.float32)
    cols["all NaN"] = np.full(16, np.nan, np.float32)
    cols["all +inf"] = np.full(16, np.inf, np.float32)
    cols["all -inf"] = np.full(16, -np.inf, np.float32)
    cols["all saturated"] = np.full(16, SAT, np.float32)
    for used in (2, 3, 4):
        c = np.full(16, np.nan, np.float32)
        c[:used] = clean[:used]
        cols[f"{used} usable"] = c
    c = clean.copy()
    c[[1, 5, 9]] = [np.nan, np.inf, -np.inf]
    cols["NaN and inf among good"] = c
    c = clean.copy()
    c[::3] = SAT + 0.1
    cols["saturated highlights"] = c
    c = clean.copy()
    c[2] += 0.4  # one strong highlight
    c[7] *= 0.3  # one partial shadow
    cols["highlight and partial shadow"] = c
    cols["outside the mask"] = clean.copy()
    names = list(cols)
    images = np.stack([cols[n] for n in names], axis=1)[:, None, :]  # (16, 1, pixels)
    mask = np.array([[n != "outside the mask" for n in names]])
    fast = _fast(images, lights, mask, SHADOW_K)
    ref = _reference(images, lights, mask, SHADOW_K)
    _compare(fast, ref, max_flips=0)
    valid = dict(zip(names, fast["valid"], strict=True))
    assert not any(valid[n] for n in names if n.startswith("all") or n.startswith("outside"))
    assert not valid["2 usable"] and valid["3 usable"] and valid["4 usable"]
    assert valid["NaN and inf among good"] and valid["highlight and partial shadow"]


def test_ill_conditioned_subsets_and_refused_drops_match_the_reference() -> None:
    """Lights near a plane: ten on one great circle, three just off it (elevation 88.6°), so
    that the set's condition number is 87 and subsets left by a few drops exceed the limit of
    100. A highlight drop that does so is final (the pixel turns invalid); a partial-shadow
    drop that would is not made (the pixel keeps its observation and its fit). The scene
    reaches both branches of the reference, and the fast fit agrees with it pixel for pixel."""
    from rti_rig.core.geometry import direction_from_az_el

    rng = np.random.default_rng(11)
    az = np.concatenate([np.zeros(5), np.full(5, 180.0), [80.0, 90.0, 100.0]])
    el = np.concatenate([np.linspace(15, 85, 5), np.linspace(20, 80, 5), [88.6] * 3])
    lights = direction_from_az_el(az, el)
    assert 80 < np.linalg.cond(lights) < COND
    p = 1500
    normals = rng.normal(size=(p, 3)) * [0.2, 0.2, 1.0]
    normals[:, 2] = np.abs(normals[:, 2]) + 0.5
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    obs = 0.6 * np.maximum(lights @ normals.T, 0.0)
    obs += rng.normal(0, 0.003, obs.shape)
    darken = rng.random(obs.shape) < 0.15  # slightly: darker than the fit, not a shadow
    obs[darken] *= rng.uniform(0.9, 0.99, darken.sum())
    brighten = rng.random(obs.shape) < 0.1
    obs[brighten] += rng.uniform(0.05, 0.3, brighten.sum())
    images = obs.astype(np.float32)[:, None, :]
    mask = np.ones((1, p), bool)
    events: list[str] = []
    with pytest.warns(IllConditionedFitWarning):  # the light set: near the limit
        fast = _fast(images, lights, mask, SHADOW_K)
    ref = _reference(images, lights, mask, SHADOW_K, events)
    assert "partial-shadow drop refused" in events
    assert "highlight drop left it unsolvable" in events
    _compare(fast, ref, max_flips=0)


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


def test_the_kernel_keeps_the_solvers_bound_margin() -> None:
    """The kernel holds its own copy of the conditioning bound's margin (numba's cache is keyed
    by the kernel's file alone, so a constant imported from another module could go stale in
    it): it must equal the numpy solver's."""
    from rti_rig.reconstruct import normal_equations, robust_kernel

    assert robust_kernel._BOUND_MARGIN == normal_equations._BOUND_MARGIN
