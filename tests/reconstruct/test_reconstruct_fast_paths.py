"""The lean paths of the fits give what a plain float64 computation gives.

The least-squares photometric stereo works a cache-sized chunk of pixels at a time and takes
its residual from the normal equations where float32 resolves it; robust photometric stereo
downdates its normal equations instead of rebuilding them; linear fits write their product
straight into the output. Each is checked here against the obvious computation.
"""

from __future__ import annotations

import numpy as np

from rti_rig.reconstruct import fit_photometric_stereo
from rti_rig.reconstruct.hsh import fit_hsh
from rti_rig.reconstruct.photometric_stereo import LS_CHUNK_BYTES
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals


def _glossy(size: int, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    lights = fibonacci_lights(n)
    normals, _ = sphere_normals(size, size)
    images = render(normals, 0.6, lights, specular=0.8, shininess=40.0)
    images += np.random.default_rng(seed).normal(0, 0.003, images.shape).astype(np.float32)
    return images.astype(np.float32), lights


def _float64_least_squares(images: np.ndarray, lights: np.ndarray) -> tuple[np.ndarray, ...]:
    n = images.shape[0]
    g = images.reshape(n, -1).astype(np.float64)
    b = np.linalg.pinv(lights) @ g
    b[2] = np.maximum(b[2], 0.0)
    rms = np.sqrt(np.mean((lights @ b - g) ** 2, axis=0))
    return b, rms


def _assert_matches_float64(res, b: np.ndarray, rms: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Residual to 1e-3 and normals to 0.05° of the float64 least squares; the valid mask."""
    v = res.valid.ravel()
    assert v.mean() > 0.99
    np.testing.assert_allclose(res.residual.ravel()[v], rms[v], rtol=1e-3, atol=1e-7)
    n64 = (b / np.linalg.norm(b, axis=0)).T
    cos = np.sum(res.normals.reshape(-1, 3)[v] * n64[v], axis=1)
    assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < 0.05
    return v


def test_least_squares_residual_and_normals_match_float64() -> None:
    """Many chunks (the image is wider than one), noisy glossy data: the residual taken from
    the normal equations agrees with the direct float64 residual to 1e-3."""
    images, lights = _glossy(220, 24)
    assert LS_CHUNK_BYTES // (4 * 24) < 220 * 220  # more than one chunk
    res = fit_photometric_stereo(images, lights)
    _assert_matches_float64(res, *_float64_least_squares(images, lights))


def _float64_albedo(images: np.ndarray, lights: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Least-squares albedo per channel given the normal ``b / |b|``: ``n.L^T I / n^T G n``."""
    n_img = images.shape[0]
    n = b / np.linalg.norm(b, axis=0)
    shade = lights @ n  # (N, P)
    flat = images.reshape(n_img, n.shape[1], -1).astype(np.float64)
    return np.einsum("kp,kpc->pc", shade, flat) / np.sum(shade * shade, axis=0)[:, None]


def test_least_squares_albedo_and_clamped_normals_match_float64() -> None:
    """The chunked fit takes the albedo as |b| and the residual as I.I - b.L^T I, which hold
    only while b solves the normal equations. A quarter of the pixels here are black
    background with the dark level subtracted (zero-mean noise, as float input after a dark
    frame is): about half of them get a least-squares b facing away from the camera (b_z < 0,
    clamped to 0), where those identities fail. Their residual, normal and albedo must still
    be those of a float64 least squares with the clamped b, grey and colour, over several
    chunks."""
    images, lights = _glossy(220, 24, seed=2)
    n_img = images.shape[0]
    flat = images.reshape(n_img, -1)
    away = np.random.default_rng(5).choice(flat.shape[1], flat.shape[1] // 4, replace=False)
    flat[:, away] = np.random.default_rng(6).normal(0, 0.01, (n_img, away.size))
    for colour in (False, True):
        stack = np.stack([images, 0.5 * images, 0.8 * images], axis=-1) if colour else images
        res = fit_photometric_stereo(stack, lights)
        b, rms = _float64_least_squares(stack.mean(axis=-1) if colour else images, lights)
        assert (b[2, away] == 0.0).mean() > 0.3 and (b[2] > 0).mean() > 0.7  # both paths
        v = _assert_matches_float64(res, b, rms)
        alb = _float64_albedo(stack, lights, b)
        got = res.albedo.reshape(alb.shape[0], -1)
        np.testing.assert_allclose(got[v], alb[v], rtol=1e-4, atol=1e-6)


def test_least_squares_excludes_saturated_and_nan_pixels_in_any_chunk() -> None:
    """Bad observations scattered over several chunks: those pixels are fitted on their other
    observations only, exactly like a float64 least squares on those observations."""
    images, lights = _glossy(220, 24, seed=1)
    images *= 0.9 / images.max()  # nothing saturated but the values set below
    rng = np.random.default_rng(3)
    flat = images.reshape(24, -1)
    picks = rng.choice(flat.shape[1], 40, replace=False)
    for j, p in enumerate(picks):
        flat[j % 24, p] = np.nan if j % 2 else 1.0
    res = fit_photometric_stereo(images, lights, saturation=1.0)
    for p in picks:
        keep = np.isfinite(flat[:, p]) & (flat[:, p] < 1.0)
        b = np.linalg.lstsq(lights[keep], flat[keep, p].astype(np.float64), rcond=None)[0]
        b[2] = max(b[2], 0.0)
        y, x = divmod(int(p), 220)
        assert res.used_lights[y, x] == keep.sum()
        if res.valid[y, x]:
            np.testing.assert_allclose(res.normals[y, x], b / np.linalg.norm(b), atol=1e-4)
    clean = np.ones(flat.shape[1], bool)
    clean[picks] = False
    assert np.all(res.used_lights.ravel()[clean & res.valid.ravel()] == 24)


def test_linear_fit_written_in_place_equals_product() -> None:
    """Colour HSH3 into a caller's array (and a new one): the plain product, exactly."""
    images, lights = _glossy(40, 30)
    colour = np.stack([images, 0.5 * images, 0.25 * images], axis=-1)
    out = np.full((16, 40, 40, 3), np.nan, dtype=np.float32)
    model = fit_hsh(colour, lights, 3, out=out, tile_rows=7)
    assert model.coefficients is out
    fresh = fit_hsh(colour, lights, 3).coefficients
    np.testing.assert_allclose(out, fresh, rtol=1e-5, atol=1e-6)  # BLAS blocking differs
    from rti_rig.core.rti_bases import hsh_basis
    from rti_rig.reconstruct.solve import solve_matrix

    w, _ = solve_matrix(hsh_basis(lights, 3), "hsh3")
    expected = np.tensordot(w, colour.astype(np.float64), axes=(1, 0))
    np.testing.assert_allclose(out, expected, rtol=1e-4, atol=1e-5)


def _cone_lights(n: int, half_deg: float) -> np.ndarray:
    """``n`` lights within ``half_deg`` of an axis tilted 40° from the zenith: accepted by the
    fit, but worse-conditioned than a dome (condition ~17 at 10°)."""
    rng = np.random.default_rng(0)
    th = np.radians(rng.uniform(0, half_deg, n))
    az = rng.uniform(0, 2 * np.pi, n)
    v = np.stack([np.sin(th) * np.cos(az), np.sin(th) * np.sin(az), np.cos(th)], 1)
    t = np.radians(40.0)  # rotate about y: the cone's axis leans towards +x
    rot = np.array([[np.cos(t), 0, np.sin(t)], [0, 1, 0], [-np.sin(t), 0, np.cos(t)]])
    return v @ rot.T


def test_least_squares_residual_unbiased_on_an_ill_conditioned_light_set() -> None:
    """The residual's short form ``I.I - b.L^T I`` is first order in the float32 rounding of
    ``b``, which grows with the light set's conditioning: on a 10° cone (condition ~17) it was
    biased by ~1e-4 of the residual, every pixel the same way. Such sets take the stationary
    form: the residual matches float64 to ~1e-6 in the median."""
    lights = _cone_lights(24, 10.0)
    assert 10 < np.linalg.cond(lights) < 30
    rng = np.random.default_rng(3)
    n = rng.normal(size=(3, 128 * 128))
    n[2] = np.abs(n[2]) + 0.3
    n /= np.linalg.norm(n, axis=0)
    clean = (lights @ n) * rng.uniform(0.2, 1.0, n.shape[1])
    q, _ = np.linalg.qr(lights)
    noise = rng.normal(size=clean.shape)
    noise -= q @ (q.T @ noise)  # the part no normal explains: the residual is this
    noise *= np.sqrt(0.013 * np.sum(clean**2, 0) / np.sum(noise**2, 0))
    images = (clean + noise).astype(np.float32).reshape(24, 128, 128)
    res = fit_photometric_stereo(images, lights)
    _, rms = _float64_least_squares(images, lights)
    rel = res.residual.ravel() / rms - 1.0
    assert abs(np.median(rel)) < 2e-5


def test_least_squares_finite_value_too_large_to_square() -> None:
    """A finite observation whose square overflows float32 flags its pixel for the per-pixel
    path (as a NaN would): no overflow warning escapes, the pixel keeps every light and gets
    the least-squares normal of its values."""
    import warnings

    images, lights = _glossy(16, 24, seed=4)
    images[5, 8, 8] = 3e19
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = fit_photometric_stereo(images, lights)
    b = np.linalg.lstsq(lights, images[:, 8, 8].astype(np.float64), rcond=None)[0]
    assert res.used_lights[8, 8] == 24
    np.testing.assert_allclose(res.normals[8, 8], b / np.linalg.norm(b), atol=1e-5)
