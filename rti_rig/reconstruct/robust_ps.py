"""Robust photometric stereo, one cache-sized chunk of pixels at a time.

The rules (shadows, saturation, highlights, partial shadows) are those of
:mod:`rti_rig.reconstruct.photometric_stereo`'s module docstring; this module is how they are
computed fast. Measured at 512² × 48 lights, the former whole-band implementation took ~185× a
same-shape matrix product; the costs were memory traffic (every pass gathered the active
pixels' (A, N) rows out of a 50 MB array, built several (A, N) temporaries and sorted every row
for its median) and Python-level work per pass. Here:

* **Chunks in the cache.** A chunk of :data:`CHUNK_PIXELS` pixels, in the band's own
  light-major layout (N, c) (no transposed copy of the band), goes through every pass of both
  rules and its outputs (normals, albedo, residual) while it is in the cache. Reductions over
  the lights run along the first axis, which numpy vectorises across pixels.
* **Unused observations are NaN** in a working copy of the chunk: a residual ``g - L b`` is then
  NaN exactly where an observation is not used, so ``fmax``/``fmin`` reductions and comparisons
  skip them without masks (a masked ``where`` costs ~10× an arithmetic pass in numpy).
* **The median only where it matters.** A highlight can be dropped only where some residual
  exceeds the floor; there the threshold is the floor itself whenever
  ``k * 1.4826 * median <= floor``, which is decided exactly by *counting* the residuals at or
  below the float32 cut at which that product first exceeds the floor (the median is at most
  the cut iff more than half of the used residuals are). For the other pixels six counting
  bisections bracket the median; only pixels with a compared value between the thresholds of
  the bracket's two ends (~5 % on the glossy benchmark scene) sort their |residuals| (as finite
  float32, which numpy sorts with SIMD; NaN would make it 5× slower). A sort of a row of ~48
  costs about as much as a dozen counting passes. The same holds for the partial-shadow rule
  with its own scale.
* **Downdated normal equations**, as before: a pass removes the few dropped observations from
  each pixel's sums (per-drop sums by ``bincount``; dense products over the drop mask measured
  1.4× slower) instead of rebuilding them; only pixels that changed are solved again (without
  eigenvalues where a bound shows the conditioning, see ``normal_equations``) and only they are
  visited in the next pass.
* **Albedo from the normal equations**: with every light's direction a unit vector, the
  least-squares albedo over the used observations is ``n . (sum I l) / n^T (sum l l^T) n``,
  both sums already at hand, so grey albedo needs no pass over the data.

What remains (measured at 512² × 48, ~100× a same-shape product): the passes themselves. The
glossy scene drops ~9 observations per pixel over ~5 highlight passes; each pass of a pixel
costs its residuals, counts, a few bisections and the downdate of its drops, ~100 ns each in
numpy, against the product's ~0.5 ns per observation. Reaching 30× would take fewer passes (a
different estimator) or compiled per-pixel loops, not more vectorisation.

The decisions are the original ones: the same float32 residuals compared with the same float32
thresholds (``fl32(k * fl32(1.4826 * median))``, floored), the same lower median, the same
darkest-first choice. Results can differ only where a float rounding of a different (but
equally exact) summation order lands on a threshold; tests/reconstruct check the fit against
a slow per-pixel reference implementation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rti_rig.reconstruct.normal_equations import light_products, solve_normal_equations

#: Pixels per chunk: (N, chunk) float32 work arrays of a few MB stay in the L3 cache through all
#: passes (measured at 48 lights, CPU time: 8192–16384 best, 4096 +13 %, 32768 +9 %; smaller
#: chunks pay numpy's per-call overhead, ~100 calls per pass).
CHUNK_PIXELS = 16384
#: Above this fraction of a chunk's pixels active, a pass computes every pixel's residuals rather
#: than gathering the active ones' columns first.
DENSE_FRACTION = 0.6
#: Counting bisections that bracket a median before any row is sorted (see ``_thresholds``):
#: on the glossy benchmark scene 6 leave ~5 % of the rows to sort (4: 34 %, 8: 1.4 %).
BRACKET_STEPS = 6
#: Scale of the median absolute deviation to a Gaussian sigma (as float32 in the thresholds).
MAD_SCALE = 1.4826
#: Stand-in for an unused observation's |residual| when a chunk's rows are sorted: finite, so
#: numpy's SIMD sort applies, and above any real residual.
_BIG = np.float32(3.0e38)


@dataclass(frozen=True)
class RobustRules:
    """Thresholds of the robust fit in the stack's units (see photometric_stereo's docstring)."""

    dark: float
    saturation: float | None
    highlight_k: float
    floor: float
    max_passes: int
    cond_limit: float
    shadow_k: float | None
    shadow_min_kept: int
    eps_b: float


def threshold_cut(scale: float, floor: float) -> np.float32:
    """The largest float32 ``m >= 0`` with ``fl32(scale * fl32(MAD_SCALE * m)) <= fl32(floor)``.

    The threshold of a pixel is ``max(fl32(scale * fl32(MAD_SCALE * median)), floor)`` in
    float32; it is exactly the floor iff ``median <= cut`` (the product is monotone in the
    median), so a count of residuals at or below the cut decides it without the median.
    Found by bisection over the float32 bit patterns (monotone for non-negative floats).
    """
    f_floor = np.float32(floor)
    s32, c32 = np.float32(scale), np.float32(MAD_SCALE)

    def ok(bits: int) -> bool:
        m = np.array([bits], dtype=np.int32).view(np.float32)[0]
        with np.errstate(over="ignore"):
            return bool(s32 * (c32 * m) <= f_floor)

    lo, hi = 0, 0x7F800000  # 0.0 and +inf
    if not ok(lo):
        return np.float32(-1.0)  # never the floor (a negative floor): always the median
    if ok(hi):
        return np.float32(np.inf)
    while hi - lo > 1:  # invariant: ok(lo), not ok(hi)
        mid = (lo + hi) // 2
        if ok(mid):
            lo = mid
        else:
            hi = mid
    return np.array([lo], dtype=np.int32).view(np.float32)[0]


def _count(mask: NDArray[np.bool_]) -> NDArray[Any]:
    """True entries per column: summed as uint8 when the column is short enough (numpy's
    fastest reduction over the first axis, ~5× an int32 one), int32 otherwise."""
    if mask.shape[0] < 256:
        return mask.view(np.uint8).sum(axis=0, dtype=np.uint8)
    return np.add.reduce(mask, axis=0, dtype=np.int32)


def _scaled(v: NDArray[np.float32], scale: float, floor32: np.float32) -> NDArray[np.float32]:
    """The threshold of a median ``v``, with the float32 roundings of the rule."""
    return np.maximum(np.float32(scale) * (np.float32(MAD_SCALE) * v), floor32)


def _thresholds(
    sub: NDArray[np.float32],
    counts: NDArray[Any],
    scale: float,
    floor32: np.float32,
    cut: np.float32,
    decide: NDArray[np.float32],
) -> NDArray[np.float32]:
    """Per column of the residuals ``sub`` (N, k) (NaN: unused; ``counts`` used ones), a
    threshold that decides ``decide > threshold`` (``decide`` (M, k): the values the rule
    compares) exactly as ``max(fl32(scale * fl32(MAD_SCALE * median |r|)), floor)`` does, with
    the lower median (index ``(count - 1) // 2`` of the sorted used values).

    Most columns need no median: where a count against ``cut`` (:func:`threshold_cut`) shows
    the median at most ``cut``, the threshold is the floor. For the others the median is
    bracketed by :data:`BRACKET_STEPS` counting bisections (``median <= x`` iff more than
    ``(count - 1) // 2`` used values are ``<= x``): where no value of ``decide`` lies between
    the thresholds of the bracket's ends, the upper end's threshold decides identically. Only
    the rest (~5 % on the glossy benchmark scene) is sorted for the exact median: a sort of
    rows of ~48 costs as much as a dozen counting passes.
    """
    absr = np.abs(sub)
    mid = (counts - 1) // 2
    small = _count(absr <= cut)  # NaN compares False
    thr = np.full(sub.shape[1], floor32, dtype=np.float32)
    hard = np.flatnonzero(small <= mid)
    if hard.size == 0:
        return thr
    x = np.take(absr, hard, axis=1)
    mid_h = mid[hard]
    if cut > 0:
        lo = np.full(hard.size, cut, dtype=np.float32)  # median > lo (the count above)
        hi = np.fmax.reduce(x, axis=0)  # median <= hi (the largest used value)
        for _ in range(BRACKET_STEPS):
            xm = np.sqrt(lo) * np.sqrt(hi)
            le = _count(x <= xm[None, :]) > mid_h
            hi = np.where(le, xm, hi)
            lo = np.where(le, lo, xm)
        t_lo, t_hi = _scaled(lo, scale, floor32), _scaled(hi, scale, floor32)
        d = decide if hard.size == thr.size else np.take(decide, hard, axis=1)
        between = np.logical_or.reduce((d > t_lo) & (d <= t_hi), axis=0)
        thr[hard] = t_hi
        exact = np.flatnonzero(between)
    else:  # a zero or negative floor: no bracket from below, sort them all
        exact = np.arange(hard.size)
    if exact.size:
        xe = x if exact.size == hard.size else np.take(x, exact, axis=1)
        np.fmin(xe, _BIG, out=xe)  # NaN (unused) -> BIG, sorted last
        xs = np.sort(np.ascontiguousarray(xe.T), axis=1)
        med = xs[np.arange(exact.size), np.clip(mid_h[exact], 0, sub.shape[0] - 1)]
        med = np.where(counts[hard[exact]] > 0, med, np.float32(0.0))
        thr[hard[exact]] = _scaled(med, scale, floor32)
    return thr


class _Chunk:
    """The working state of one chunk: observations with unused ones as NaN, the normal
    equations of the used ones, the fit and its validity."""

    def __init__(
        self,
        g: NDArray[np.float32],
        inside: NDArray[np.bool_],
        lights: NDArray[np.float64],
        ll6: NDArray[np.float64],
        rules: RobustRules,
    ) -> None:
        self.g = g  # (N, c) the band's values (a view; never written)
        self.lights = lights
        self.l32 = lights.astype(np.float32)
        self.l32t = np.ascontiguousarray(self.l32.T)
        self.ll6 = ll6
        self.ll6t = np.ascontiguousarray(ll6.T)
        self.lights_t = np.ascontiguousarray(lights.T)
        self.rules = rules
        sat = np.float32(np.inf if rules.saturation is None else rules.saturation)
        with np.errstate(invalid="ignore"):
            w = g > np.float32(rules.dark)  # NaN: False
            w &= g < sat  # +inf and saturated: False
            if not inside.all():
                w &= inside[None, :]
            # unused observations become NaN (0 * inf), used ones keep their value
            # C order whatever the caller's layout (a transposed stack is F-ordered)
            self.gn = np.minimum(g, w * np.float32(np.inf), order="C")
        assert self.gn.flags.c_contiguous  # written through flat indices (see _remove)
        with np.errstate(invalid="ignore"):
            rhs = self.l32t @ (g * w)
        if not np.isfinite(rhs).all():  # NaN/inf observations (unused): zero them properly
            rhs = self.l32t @ np.where(w, g, np.float32(0.0))
        self.rhs = rhs.astype(np.float64)
        self.m = self.ll6t @ w.astype(np.float64)
        self.count = np.add.reduce(w, axis=0, dtype=np.int32)
        self.b, self.ok = solve_normal_equations(
            self.m, self.rhs, self.count, rules.cond_limit, light_major=True
        )  # b (3, c)

    def residuals(
        self, act: NDArray[np.intp]
    ) -> tuple[NDArray[np.intp], NDArray[np.float32], NDArray[np.bool_] | None]:
        """``g - L b`` (N, s) NaN where an observation is unused, of the pixels ``span``:
        ``act`` itself, or every pixel of the chunk when most are active (a gather of the
        active columns costs more than computing the others too); then also the mask of
        the active ones among them (None: all are)."""
        c = self.gn.shape[1]
        if act.size == c:
            span, ga, ba, inact = act, self.gn, self.b, None
        elif act.size > DENSE_FRACTION * c:
            span, ga, ba = np.arange(c), self.gn, self.b
            inact = np.ones(c, dtype=bool)
            inact[act] = False
        else:
            span, inact = act, None
            ga, ba = np.take(self.gn, act, axis=1), np.take(self.b, act, axis=1)
        r = self.l32 @ ba.astype(np.float32)
        np.subtract(ga, r, out=r)
        return span, r, inact

    def _remove(self, cols: NDArray[np.intp], drop: NDArray[np.bool_]) -> tuple[NDArray, ...]:
        """Remove the observations ``drop`` (N, k) of pixels ``cols`` from their normal
        equations and mark them unused; returns the pixels' updated ``m``, ``rhs``, ``count``.

        A downdate by the few removed terms (exact in float64), not a rebuild over all N: drops
        are sparse (a few per pixel), so per-drop sums (``bincount``) beat a dense product."""
        k = cols.size
        light, local = np.divmod(np.flatnonzero(drop), k)
        values = self.g[light, cols[local]].astype(np.float64)
        m_c = self.m[:, cols]
        # per component from a contiguous table: bincount wants contiguous weights
        for j in range(6):
            m_c[j] -= np.bincount(local, weights=np.take(self.ll6t[j], light), minlength=k)
        rhs_c = self.rhs[:, cols]
        for j in range(3):
            w = values * np.take(self.lights_t[j], light)
            rhs_c[j] -= np.bincount(local, weights=w, minlength=k)
        count_c = self.count[cols] - np.bincount(local, minlength=k).astype(np.int32)
        self.m[:, cols], self.rhs[:, cols], self.count[cols] = m_c, rhs_c, count_c
        # flat indices into the (contiguous) working copy: ~2× faster than a 2-D fancy index
        self.gn.reshape(-1)[light * self.gn.shape[1] + cols[local]] = np.nan
        return m_c, rhs_c, count_c

    def highlights(self) -> None:
        """Rule 3: drop observations brighter than the fit by more than the threshold,
        refitting the pixels that dropped any, up to ``max_passes`` times."""
        rules = self.rules
        floor32 = np.float32(rules.floor)
        cut = threshold_cut(rules.highlight_k, rules.floor)
        act = np.flatnonzero(self.ok)
        for _ in range(rules.max_passes):
            if act.size == 0:
                break
            span, r, inact = self.residuals(act)
            top = np.fmax.reduce(r, axis=0)
            if inact is not None:
                top[inact] = -np.inf
            over = top > floor32
            hit = np.flatnonzero(over)
            if hit.size == 0:
                break
            if inact is None and hit.size > DENSE_FRACTION * span.size:
                # most columns can drop: keep them all rather than gather the hits; the others
                # get a count of 0, hence the floor as threshold, which none of theirs exceeds
                counts = np.where(over, self.count[span], 0)
                sub, hit = r, np.arange(span.size)
            else:
                sub = np.take(r, hit, axis=1)
                counts = self.count[span[hit]]
            thr = _thresholds(sub, counts, rules.highlight_k, floor32, cut, sub)
            drop = sub > thr[None, :]  # NaN (unused): False
            changed = np.flatnonzero(np.logical_or.reduce(drop, axis=0))
            if changed.size == 0:
                break
            if changed.size < drop.shape[1]:
                drop = np.take(drop, changed, axis=1)
            cols = span[hit[changed]]
            m_c, rhs_c, count_c = self._remove(cols, drop)
            b_c, ok_c = solve_normal_equations(
                m_c, rhs_c, count_c, rules.cond_limit, light_major=True
            )
            self.b[:, cols], self.ok[cols] = b_c, ok_c
            act = cols[ok_c]

    def partial_shadows(self) -> None:
        """Rule 4: per pass, drop each pixel's darkest observation if it is darker than the
        fit by more than the threshold (while more than ``shadow_min_kept`` remain), unless
        that leaves the pixel unsolvable."""
        rules = self.rules
        assert rules.shadow_k is not None
        floor32 = np.float32(rules.floor)
        cut = threshold_cut(rules.shadow_k, rules.floor)
        act = np.flatnonzero(self.ok)
        for _ in range(rules.max_passes):
            if act.size == 0:
                break
            span, r, inact = self.residuals(act)
            low = np.fmin.reduce(r, axis=0)
            if inact is not None:
                low[inact] = np.inf
            hit = np.flatnonzero((low < -floor32) & (self.count[span] > rules.shadow_min_kept))
            if hit.size == 0:
                break
            sub = np.take(r, hit, axis=1)
            dark = -low[hit]
            thr = _thresholds(
                sub, self.count[span[hit]], rules.shadow_k, floor32, cut, dark[None, :]
            )
            sel = np.flatnonzero(dark > thr)
            if sel.size == 0:
                break
            # the first observation at the minimum, as argmin would pick it
            worst = np.argmax(np.take(sub, sel, axis=1) == low[hit[sel]][None, :], axis=0)
            cols = span[hit[sel]]
            m_c = self.m[:, cols] - self.ll6[worst].T
            rhs_c = (
                self.rhs[:, cols] - self.g[worst, cols].astype(np.float64) * self.lights[worst].T
            )
            count_c = self.count[cols] - 1
            b_c, ok_c = solve_normal_equations(
                m_c, rhs_c, count_c, rules.cond_limit, light_major=True
            )
            # a drop that leaves the pixel unsolvable (ill-conditioned subset) is not made: the
            # pixel keeps its observation and its earlier fit rather than turning invalid
            keep, wk = cols[ok_c], worst[ok_c]
            self.gn[wk, keep] = np.nan
            self.m[:, keep], self.rhs[:, keep] = m_c[:, ok_c], rhs_c[:, ok_c]
            self.count[keep] = count_c[ok_c]
            self.b[:, keep] = b_c[:, ok_c]
            act = keep

    def outputs(
        self, flat: NDArray[np.float32] | None, inside: NDArray[np.bool_]
    ) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray[np.bool_]]:
        """Normals (c, 3), albedo (c, C), RMS residual (c,), used count (c,) and validity;
        invalid pixels get the view axis, zero albedo, residual and count. ``flat`` (N, c, C)
        holds the colour values (None for grey: the albedo comes from the normal equations)."""
        b = self.b
        b[2] = np.maximum(b[2], 0.0)  # a normal facing away from the camera is unseen
        norm = np.sqrt(np.einsum("ij,ij->j", b, b))
        ok = self.ok & inside & (norm > self.rules.eps_b)
        n = b / np.where(norm > 0, norm, 1.0)
        n[:, ~ok] = np.array([[0.0], [0.0], [1.0]])
        m = self.m
        # n^T (sum l l^T) n over the used lights: the albedo's denominator
        den = (
            m[0] * n[0] * n[0]
            + m[3] * n[1] * n[1]
            + m[5] * n[2] * n[2]
            + 2.0 * (m[1] * n[0] * n[1] + m[2] * n[0] * n[2] + m[4] * n[1] * n[2])
        )
        den = np.where(den > 0, den, 1.0)
        if flat is None:
            alb = (np.einsum("ij,ij->j", n, self.rhs) / den)[:, None]
        else:
            used = ~np.isnan(self.gn)
            n_img, c, channels = flat.shape
            # all channels in one product over the (N, c * C) values of the used observations
            kept = (flat * used[:, :, None]).reshape(n_img, c * channels)
            proj = (self.l32t @ kept).reshape(3, c, channels).astype(np.float64)
            alb = np.einsum("ij,ijk->jk", n, proj) / den[:, None]
        # RMS residual of the fitted (z-clamped) b over the used observations, computed
        # directly (a difference of large sums would not resolve a good fit's residual)
        res = self.l32 @ (n * norm).astype(np.float32)
        np.subtract(self.gn, res, out=res)
        np.square(res, out=res)
        np.fmax(res, np.float32(0.0), out=res)  # NaN (unused) -> 0
        count = np.where(ok, self.count, 0)
        rms = np.sqrt(np.add.reduce(res, axis=0).astype(np.float64) / np.maximum(count, 1))
        alb[~ok] = 0.0
        rms[~ok] = 0.0
        return n.T, alb, rms, count, ok


def fit_robust_band(
    g: NDArray[np.float32],
    inside: NDArray[np.bool_],
    lights: NDArray[np.float64],
    rules: RobustRules,
    flat: NDArray[np.float32] | None = None,
    chunk: int = CHUNK_PIXELS,
) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray[np.bool_]]:
    """The robust fit of a band ``g`` (N, P) of grey values (never written; NaN, infinite and
    saturated values are not used), ``inside`` (P,) the mask, ``flat`` (N, P, C) colour values
    (unusable ones zeroed) when the albedo has several channels.

    Returns normals (P, 3), albedo (P, C), RMS residual (P,), used count (P,) and validity (P,),
    chunk by chunk (see the module docstring).
    """
    p = g.shape[1]
    channels = 1 if flat is None else flat.shape[2]
    normals = np.empty((p, 3))
    albedo = np.empty((p, channels))
    rms = np.empty(p)
    count = np.empty(p, dtype=np.int32)
    ok = np.empty(p, dtype=bool)
    ll6 = light_products(lights)
    for s in range(0, p, chunk):
        e = min(p, s + chunk)
        state = _Chunk(g[:, s:e], inside[s:e], lights, ll6, rules)
        state.highlights()
        if rules.shadow_k is not None:
            state.partial_shadows()
        out = state.outputs(None if flat is None else flat[:, s:e], inside[s:e])
        normals[s:e], albedo[s:e], rms[s:e], count[s:e], ok[s:e] = out
    return normals, albedo, rms, count, ok
