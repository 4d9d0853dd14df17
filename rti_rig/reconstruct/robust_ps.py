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

import numpy as np
from numpy.typing import NDArray

#: Scale of the median absolute deviation to a Gaussian sigma (as float32 in the thresholds).
MAD_SCALE = 1.4826


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


def fit_robust_band(
    g: NDArray[np.float32],
    inside: NDArray[np.bool_],
    lights: NDArray[np.float64],
    rules: RobustRules,
    flat: NDArray[np.float32] | None = None,
) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray[np.bool_]]:
    """The robust fit of a band ``g`` (N, P) of grey values (never written; NaN, infinite and
    saturated values are not used), ``inside`` (P,) the mask, ``flat`` (N, P, C) colour values
    (unusable ones zeroed) when the albedo has several channels.

    Returns normals (P, 3), albedo (P, C), RMS residual (P,), used count (P,) and validity (P,),
    pixel by pixel in the compiled kernel (see the module docstring).
    """
    from rti_rig.reconstruct import robust_kernel  # numba: imported by robust fits only

    p = g.shape[1]
    channels = 1 if flat is None else flat.shape[2]
    normals = np.empty((p, 3))
    albedo = np.empty((p, channels))
    rms = np.empty(p)
    count = np.empty(p, dtype=np.int32)
    ok = np.empty(p, dtype=bool)
    f32 = np.float32
    # one compiled signature: C-ordered float32 (a transposed caller's stack is copied once)
    colour = np.empty((0, 0, 0), f32) if flat is None else np.ascontiguousarray(flat, f32)
    robust_kernel.fit_pixels(
        np.ascontiguousarray(g, f32),
        np.ascontiguousarray(inside, bool),
        colour,
        np.ascontiguousarray(lights, np.float64),
        f32(rules.dark),
        f32(np.inf if rules.saturation is None else rules.saturation),
        np.array(
            [
                rules.highlight_k,
                threshold_cut(rules.highlight_k, rules.floor),
                0.0 if rules.shadow_k is None else rules.shadow_k,  # 0: rule 4 off
                rules.floor,
            ],
            dtype=f32,
        ),
        int(rules.max_passes),
        int(rules.shadow_min_kept),
        float(rules.cond_limit) ** 2,  # as normal_equations squares it
        float(rules.eps_b),
        normals,
        albedo,
        rms,
        count,
        ok,
    )
    return normals, albedo, rms, count, ok
