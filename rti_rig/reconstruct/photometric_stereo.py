"""Lambertian photometric stereo (Woodham 1980): normals and albedo from N >= 3 lights.

Model: ``I_k = rho * max(0, l_k . n)``. Per pixel, ``b = rho n`` solves the least-squares
system ``L b = I`` over the observations used; ``n = b / |b|``, ``rho = |b|`` (grey), per-channel
albedo by least squares on the fitted shading.

*Least squares* (``robust=False``) uses every light: one matrix product with ``pinv(L)`` per band
of rows. Attached shadows and highlights bias it (notes §2: 15.4° mean on DiLiGenT).

*Robust* (``robust=True``) discards, per pixel,

1. **shadows**: observations below ``dark_threshold`` (default :data:`DARK_FRACTION` of the
   stack's reference level, the 99th percentile of a pixel sample);
2. **saturated** observations at or above ``saturation`` (default: the stack's saturation
   level — none for float input, the top code value for integer input, 1.0 for
   :func:`stack_from_frames`; pass ``float("inf")`` to disable);
3. **highlights**: observations brighter than the current Lambertian fit by more than
   ``max(highlight_k * sigma, highlight_floor)``, with ``sigma = 1.4826 * median |residual|``
   over the pixel's used observations (a robust noise scale), refitting after each of up to
   ``max_passes`` passes. Only positive residuals count here: specular lobes add light.
4. **partial shadows** (``shadow_k``, default :data:`SHADOW_K`; ``None`` turns the rule off):
   then, one per pass, the observation darkest against the fit if it is darker by more than
   ``max(shadow_k * sigma, highlight_floor)``, while more than :data:`SHADOW_MIN_KEPT`
   observations remain. A pixel on the edge of a cast shadow, or lit by a weak LED, is darker
   than Lambert says yet too bright for rule 1; left in, it tilts the normal away from its
   light. Only the darkest one per pass, because a remaining highlight's pull on the fit makes
   every other observation look a little dark.

A pixel keeps at least 3 observations whose lights are not ill-conditioned (condition
number of its light subset <= ``cond_limit``), else it is marked invalid (``valid`` False,
normal (0, 0, 1), albedo 0) — never silently guessed. Pixels outside ``mask`` and all-dark
pixels are invalid too. The full light set must itself be well-conditioned, or the fit is refused:
a regularised normal would be biased towards the plane of the lights.

Per-pixel systems are solved in closed form (3 × 3 adjugate, closed-form symmetric eigenvalues
where a cheap bound cannot decide the conditioning; :mod:`rti_rig.reconstruct.normal_equations`),
vectorised over the band: no Python loop over pixels. The robust rules are computed pixel by
pixel in a compiled kernel (numba, imported only by a robust fit;
:mod:`rti_rig.reconstruct.robust_ps` says why, :mod:`rti_rig.reconstruct.robust_kernel` how).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.normal_equations import solve_weighted
from rti_rig.reconstruct.robust_ps import RobustRules, fit_robust_band
from rti_rig.reconstruct.solve import COND_LIMIT, solve_matrix
from rti_rig.reconstruct.stack import ImageStack, as_direction, channel_mean, validate_lights
from rti_rig.reconstruct.tiling import row_tiles, rows_for_budget

#: Default shadow threshold as a fraction of the stack's reference level.
DARK_FRACTION = 0.02
#: Default floor of the highlight test as a fraction of the reference level (so that a perfect
#: fit with rounding-level residuals drops nothing).
HIGHLIGHT_FLOOR_FRACTION = 0.01
#: Pixels with |b| at or below this fraction of the reference level are "all dark": invalid.
DARK_PIXEL_FRACTION = 1e-6
#: Threshold of the partial-shadow test in robust noise scales (rule 4). On by default: it turns
#: the planner's losses on the simulated tablet into ties and moves the real dome's means by at
#: most 0.1°, no verdict (docs/research/planner.md).
SHADOW_K = 3.0
#: The partial-shadow test never leaves a pixel fewer observations than this.
SHADOW_MIN_KEPT = 5


@dataclass(frozen=True)
class PSResult:
    """Normals, albedo and the evidence of a photometric-stereo fit.

    ``normals`` (H, W, 3) float32 unit vectors with z >= 0 (docs/conventions.md frame),
    ``albedo`` (H, W) or (H, W, C), ``residual`` RMS grey residual over the used observations,
    ``valid`` (H, W), ``used_lights`` (H, W) count of observations used per pixel.
    """

    normals: NDArray[np.float32]
    albedo: NDArray[np.float32]
    residual: NDArray[np.float32]
    valid: NDArray[np.bool_]
    used_lights: NDArray[np.int16]
    condition_number: float
    robust: bool
    dark_threshold: float
    saturation: float | None
    #: the partial-shadow threshold the fit applied (None: rule off, or least squares)
    shadow_k: float | None = None

    @property
    def name(self) -> str:
        return "lambert-ps-robust" if self.robust else "lambert-ps"

    @property
    def n_coefficients(self) -> int:
        return 3

    def relight(self, direction: ArrayLike) -> NDArray[np.float32]:
        """Lambertian rendering ``albedo * max(0, n . l)``; invalid pixels render black."""
        d = as_direction(direction).astype(np.float32)
        shade = np.maximum(self.normals @ d, np.float32(0.0)) * self.valid
        return (self.albedo * (shade if self.albedo.ndim == 2 else shade[..., None])).astype(
            np.float32
        )

    def summary(self) -> dict[str, float]:
        """Headline numbers for reports: valid fraction, mean used lights, median residual."""
        v = self.valid
        return {
            "valid_fraction": float(v.mean()),
            "mean_used_lights": float(self.used_lights[v].mean()) if v.any() else 0.0,
            "median_residual": float(np.median(self.residual[v])) if v.any() else float("nan"),
            "condition_number": self.condition_number,
        }


def _unit_normals(
    b: NDArray[np.float64], ok: NDArray[np.bool_], eps_b: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Normals (P, 3) with z >= 0, |b| and validity; invalid pixels get (0, 0, 1)."""
    b[:, 2] = np.maximum(b[:, 2], 0.0)  # a normal facing away from the camera is unseen
    norm = np.linalg.norm(b, axis=1)
    ok = ok & (norm > eps_b)
    n = np.where(ok[:, None], b / np.where(norm > 0, norm, 1.0)[:, None], [0.0, 0.0, 1.0])
    return n, norm, ok


def _albedo_residual_used(
    b: NDArray[np.float64],
    w: NDArray[np.bool_],
    ok: NDArray[np.bool_],
    g: NDArray[np.float32],
    flat: NDArray[np.float32],
    lights: NDArray[np.float64],
    eps_b: float,
) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray[np.bool_]]:
    """Normals, per-channel albedo, RMS residual and counts over each pixel's used lights."""
    n, norm, ok = _unit_normals(b, ok, eps_b)
    wf = w & ok[None, :]
    # float32 (N, P) work arrays, reductions over the contiguous first axis
    shade = lights.astype(np.float32) @ np.ascontiguousarray(n.T, dtype=np.float32)
    shade *= wf
    den = np.add.reduce(shade * shade, axis=0).astype(np.float64)
    den = np.where(den > 0, den, 1.0)
    channels = flat.shape[2]
    alb = np.empty((shade.shape[1], channels))
    for c in range(channels):
        alb[:, c] = np.add.reduce(shade * flat[..., c], axis=0) / den
    count = np.add.reduce(wf, axis=0, dtype=np.int32)
    res = shade * norm.astype(np.float32)[None, :]  # prediction where used, 0 elsewhere
    res -= g
    res *= wf
    np.square(res, out=res)
    rms = np.sqrt(np.add.reduce(res, axis=0).astype(np.float64) / np.maximum(count, 1))
    return n, alb, rms, count, ok


#: Bytes of observations per chunk of the least-squares pass: the chunk's (N, chunk) float32 work
#: arrays stay in the L3 cache, so the residual's extra passes cost little beyond the product
#: (measured before its arithmetic was cut: 1.5 MB gave 3.2×, 4–24 MB 3.0× a same-shape product
#: at 512² × 48).
LS_CHUNK_BYTES = 4 * 1024 * 1024
#: The least-squares residual is taken from the normal equations where it is at least this
#: fraction of ``I.I``; float32 sums are exact to ~1e-6 of ``I.I``, so its relative error stays
#: below ~1e-4 there on a well-spread light set. Smaller residuals are computed directly.
DIRECT_RESIDUAL_FRACTION = 1e-2
#: Light sets up to this condition number take the residual as ``I.I - b.L^T I`` (``b^T G b =
#: b.L^T I`` for ``b = G^-1 L^T I``); worse-conditioned ones as ``I.I - 2 b.L^T I + b^T G b``,
#: which is stationary in ``b``: the short form is first order in the rounding of the float32
#: ``b``, which grows with the conditioning (a 10° cone of lights, condition 17: a bias of
#: 1.3e-4 of the residual, against 1e-6 for the long form). Lights spread over the hemisphere
#: are far below the limit: the shared 72-LED dome 1.56, Fibonacci layouts of 6–100 1.2–1.3.
SHORT_RESIDUAL_COND = 4.0
_VIEW_AXIS = np.array([[0.0], [0.0], [1.0]], dtype=np.float32)


def _least_squares_band(
    flat: NDArray[np.float32],
    g: NDArray[np.float32],
    inside: NDArray[np.bool_],
    lights: NDArray[np.float64],
    gram: NDArray[np.float64],
    eps_b: float,
    saturation: float | None,
    normals: NDArray[np.float32] | None = None,
) -> tuple[NDArray, NDArray, NDArray, NDArray[np.bool_], NDArray[np.intp]]:
    """Least squares over all lights, a cache-sized chunk of pixels at a time.

    ``flat`` (N, P, C) is the band (never written), ``g`` (N, P) its grey values. Per chunk:
    ``L^T I`` (the one product that reads the band) and ``I.I`` (one more pass, while the chunk
    is in cache), ``b = (L^T L)^-1 L^T I``. Everything else is per pixel on 3-vectors, and uses
    that ``b`` solves the normal equations: ``b^T (L^T L) b = b.(L^T I)``, so the residual is
    ``I.I - b.(L^T I)`` and, with every light used, the albedo of the normal ``b / |b|`` is
    ``|b|`` (its least-squares value ``n.(L^T I) / n^T (L^T L) n`` reduces to it). Where ``b``
    points away from the camera and is clamped to ``b_z = 0`` it no longer solves them: those
    few pixels take the general formulas. A residual small against the signal (which float32
    cannot resolve as a difference of large sums) is computed directly, ``|L b - I|``. A pixel
    with a NaN/infinite observation (found in ``I.I``, where it propagates) or a saturated one
    (one max-reduction of the chunk) is returned in ``suspect`` for the caller's per-pixel
    path.

    Returns normals (P, 3) float32 (invalid: the view axis; written into ``normals`` when
    given), albedo (P, C), RMS residual (P,), validity (P,) and the suspect pixels' indices.
    """
    n_img, p = g.shape
    channels = flat.shape[2]
    l32 = lights.astype(np.float32)
    lt32 = np.ascontiguousarray(l32.T)
    ginv32 = np.linalg.inv(gram).astype(np.float32)
    gram32 = gram.astype(np.float32)
    sat = None if saturation is None else np.float32(saturation)
    short_residual = np.linalg.cond(gram) <= SHORT_RESIDUAL_COND**2  # cond(G) = cond(L)²
    if normals is None:
        normals = np.empty((p, 3), dtype=np.float32)
    alb = np.empty((p, channels), dtype=np.float32)
    rms = np.empty(p, dtype=np.float32)
    ok = np.empty(p, dtype=bool)
    suspect = []
    chunk = max(256, LS_CHUNK_BYTES // (4 * n_img * channels))
    # one work buffer reused by every chunk: a fresh array of this size per chunk costs more
    # in first-touch page faults than the arithmetic
    work = np.empty((n_img, min(chunk, p)), dtype=np.float32)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        # NaN/inf pixels are returned as suspect
        for s in range(0, p, chunk):
            e = min(p, s + chunk)
            gc = g[:, s:e]
            ltg = lt32 @ gc  # (3, c)
            gg = np.einsum("ij,ij->j", gc, gc)  # NaN or inf where an observation is
            bad = ~np.isfinite(gg)
            if sat is not None:
                top = np.max(flat[:, s:e].reshape(n_img, -1), axis=0)
                bad |= (top >= sat).reshape(-1, channels).any(axis=1)
            b = ginv32 @ ltg
            bl = np.einsum("ij,ij->j", b, ltg)  # b^T G b while b solves the normal equations
            clamped = np.flatnonzero(b[2] < 0)  # a normal facing away is unseen: b_z = 0
            if clamped.size:
                bk = b[:, clamped]
                bk[2] = 0.0
                b[:, clamped] = bk
            if short_residual:
                r2 = gg - bl
                if clamped.size:
                    r2[clamped] = _stationary_r2(gg[clamped], bk, ltg[:, clamped], gram32)
            else:
                r2 = _stationary_r2(gg, b, ltg, gram32)
            direct = ~(r2 >= DIRECT_RESIDUAL_FRACTION * gg)  # NaN included
            if direct.any():
                k = np.flatnonzero(direct)
                if 4 * k.size > e - s:
                    k = slice(None)
                    sub = gc
                else:
                    sub = gc[:, k]
                pred = np.matmul(l32, b[:, k], out=work[:, : sub.shape[1]])
                pred -= sub
                r2[k] = np.einsum("ij,ij->j", pred, pred)
            np.maximum(r2, np.float32(0.0), out=r2)
            r2 *= np.float32(1.0 / n_img)
            rms[s:e] = np.sqrt(r2)
            norm = np.sqrt(np.einsum("ij,ij->j", b, b))
            good = inside[s:e] & ~bad & (norm > eps_b)
            safe = np.where(norm > 0, norm, np.float32(1.0))
            nn = b / safe  # divided, not times a reciprocal: the normals of before, bit for bit
            if clamped.size:  # n^T G n where b no longer solves the normal equations
                nk = nn[:, clamped]
                sk = np.einsum("ij,ij->j", gram32 @ nk, nk)
                sk = np.where(sk > 0, sk, np.float32(1.0))
            if channels == 1:
                alb[s:e, 0] = norm
                if clamped.size:
                    alb[s + clamped, 0] = np.einsum("ij,ij->j", nk, ltg[:, clamped]) / sk
            else:
                ss = bl / (safe * safe)  # n^T G n while b solves them
                ss = np.where(ss > 0, ss, np.float32(1.0))
                if clamped.size:
                    ss[clamped] = sk
                proj = (lt32 @ flat[:, s:e].reshape(n_img, -1)).reshape(3, e - s, channels)
                alb[s:e] = np.einsum("ip,ipc->pc", nn, proj) / ss[:, None]
            if not good.all():
                nn[:, ~good] = _VIEW_AXIS
            out = normals[s:e]  # column by column: 4× cheaper than a (3, c) transpose
            out[:, 0] = nn[0]
            out[:, 1] = nn[1]
            out[:, 2] = nn[2]
            ok[s:e] = good
            if bad.any():
                suspect.append(s + np.flatnonzero(bad & inside[s:e]))
    cols = np.concatenate(suspect) if suspect else np.zeros(0, dtype=np.intp)
    return normals, alb, rms, ok, cols


def _stationary_r2(
    gg: NDArray[np.float32], b: NDArray[np.float32], ltg: NDArray[np.float32], gram32: NDArray
) -> NDArray[np.float32]:
    """``|L b - I|² = I.I - 2 b.L^T I + b^T G b`` per pixel, for any ``b`` (stationary at the
    least-squares one: the rounding of a float32 ``b`` enters it to second order only)."""
    return gg - 2.0 * np.einsum("ij,ij->j", b, ltg) + np.einsum("ij,ij->j", gram32 @ b, b)


def fit_photometric_stereo(
    images: Any,
    lights: ArrayLike,
    robust: bool = False,
    mask: ArrayLike | None = None,
    tile_rows: int | None = None,
    *,
    dark_threshold: float | None = None,
    saturation: float | None = None,
    highlight_k: float = 2.0,
    highlight_floor: float | None = None,
    max_passes: int = 10,
    cond_limit: float = COND_LIMIT,
    shadow_k: float | None = SHADOW_K,
    reference_level: float | None = None,
) -> PSResult:
    """Normals and albedo of linear ``images`` (N, H, W[, C]) under unit ``lights`` (N, 3).

    See the module docstring for the robust rules; ``shadow_k`` (rule 4) is read only by the
    robust fit, since least squares discards nothing. ``reference_level`` overrides the stack's
    own (a caller fitting band by band passes the whole acquisition's, so thresholds agree).
    Raises :class:`ReconstructionError` for fewer than 3 lights or an ill-conditioned
    (near-coplanar) light set.
    """
    if shadow_k is not None and not (np.isfinite(shadow_k) and shadow_k > 0):
        raise ReconstructionError(f"shadow_k must be a positive number, got {shadow_k!r}")
    stack = ImageStack(images, saturation_level=saturation)
    lt = validate_lights(lights, stack.n)
    _, report = solve_matrix(lt, "photometric stereo", "refuse", cond_limit)
    h, wd = stack.height, stack.width
    if mask is None:
        inside_all = np.ones((h, wd), dtype=bool)
    else:
        inside_all = np.asarray(mask, dtype=bool)
        if inside_all.shape != (h, wd):
            raise ReconstructionError(f"mask has shape {inside_all.shape}, images are {(h, wd)}")
    ref = stack.reference_level() if reference_level is None else float(reference_level)
    dark = float(dark_threshold) if dark_threshold is not None else DARK_FRACTION * ref
    if saturation is None:
        saturation = stack.saturation_level
    floor = HIGHLIGHT_FLOOR_FRACTION * ref if highlight_floor is None else float(highlight_floor)
    eps_b = DARK_PIXEL_FRACTION * ref

    # every band writes every pixel of these (invalid ones too): no fill pass needed
    normals = np.empty((h, wd, 3), dtype=np.float32)
    albedo = np.empty((h, wd, stack.channels), dtype=np.float32)
    residual = np.empty((h, wd), dtype=np.float32)
    valid = np.empty((h, wd), dtype=bool)
    used = np.empty((h, wd), dtype=np.int16)
    gram = lt.T @ lt
    # the least-squares fit keeps a few (N, pixels) work arrays besides the float32 band; the
    # robust kernel works in blocks of 128 pixels (robust_kernel.BLOCK_PIXELS) and needs less,
    # but the same band keeps the memory figures of docs/reconstruction.md valid for both
    rows = tile_rows or rows_for_budget(stack.n, wd, stack.channels + 12)
    rules = RobustRules(
        dark=dark,
        saturation=saturation,
        highlight_k=float(highlight_k),
        floor=floor,
        max_passes=max_passes,
        cond_limit=cond_limit,
        shadow_k=None if shadow_k is None else float(shadow_k),
        shadow_min_kept=SHADOW_MIN_KEPT,
        eps_b=eps_b,
    )
    for sl in row_tiles(h, rows):
        band = stack.rows(sl, strict=False, copy=False)  # (N, r, W, C), maybe a view
        r = band.shape[1]
        inside = inside_all[sl].ravel()
        if not robust:
            flat = band.reshape(stack.n, r * wd, stack.channels)
            g = channel_mean(flat) if stack.channels > 1 else flat[..., 0]
            n_t, alb, rms, ok, cols = _least_squares_band(
                flat,
                g,
                inside,
                lt,
                gram,
                eps_b,
                stack.saturation_level,
                normals[sl].reshape(r * wd, 3),  # a view: the normals are written in place
            )
            count = np.full(ok.shape, stack.n)
            if cols.size:
                # pixels with an excluded observation (NaN, saturated): least squares on the
                # others only, per pixel
                vals = flat[:, cols]  # (N, k, C) copy
                bad_c = stack.unusable(vals)
                if bad_c is None:  # flagged only for a finite value whose square overflows
                    bad_c = np.zeros(vals.shape, dtype=bool)  # float32 (> ~1.8e19): all used
                vals[bad_c] = 0.0
                usable = ~np.logical_or.reduce(bad_c, axis=2)
                gc = channel_mean(vals) if stack.channels > 1 else vals[..., 0]
                bc, okc = solve_weighted(np.ascontiguousarray(gc.T), usable.T, lt, cond_limit)
                with np.errstate(over="ignore"):  # such a pixel's residual is inf, as before
                    n_c, alb_c, rms_c, count_c, ok_c = _albedo_residual_used(
                        bc, usable, okc, gc, vals, lt, eps_b
                    )
                n_t[cols], alb[cols], rms[cols] = n_c, alb_c, rms_c
                count[cols], ok[cols] = count_c, ok_c
            alb[~ok] = 0.0
            albedo[sl] = alb.reshape(r, wd, stack.channels)
            rms[~ok] = 0.0
            residual[sl] = rms.reshape(r, wd)
            valid[sl] = ok.reshape(r, wd)
            used[sl] = np.where(ok, count, 0).reshape(r, wd)
            continue
        flat = band.reshape(stack.n, r * wd, stack.channels)
        if stack.grey:
            # NaN, infinite and saturated values are recognised (and not used) pixel by pixel
            # by the robust kernel itself: no pass over the band here
            g, colour = flat[..., 0], None
        else:
            bad = stack.unusable(band)  # NaN / saturated: zeroed (in a copy), excluded below
            if bad is not None:
                flat = np.where(bad, np.float32(0.0), band).reshape(flat.shape)
            g = channel_mean(flat)
            if bad is not None:
                bad3 = bad.reshape(stack.n, r * wd, -1)
                # channel by channel: a reduction over the short last axis is ~10× slower
                usable = ~bad3[..., 0]
                for ch in range(1, bad3.shape[2]):
                    usable &= ~bad3[..., ch]
                g = np.where(usable, g, np.float32(np.nan))  # an observation not used
            colour = flat
        n, alb, rms, count, ok = fit_robust_band(g, inside, lt, rules, colour)
        normals[sl] = n.reshape(r, wd, 3)
        albedo[sl] = alb.reshape(r, wd, stack.channels)
        residual[sl] = rms.reshape(r, wd)
        valid[sl] = ok.reshape(r, wd)
        used[sl] = count.reshape(r, wd)
    return PSResult(
        normals=normals,
        albedo=albedo[..., 0] if stack.grey else albedo,
        residual=residual,
        valid=valid,
        used_lights=used,
        condition_number=report.condition_number,
        robust=robust,
        dark_threshold=dark,
        saturation=saturation,
        shadow_k=shadow_k if robust else None,
    )
