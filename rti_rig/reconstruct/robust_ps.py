"""Robust photometric stereo: the rules' thresholds and the fit of a band.

The rules (shadows, saturation, highlights, partial shadows) are those of
:mod:`rti_rig.reconstruct.photometric_stereo`'s module docstring; they are computed pixel by
pixel in a compiled kernel, :mod:`rti_rig.reconstruct.robust_kernel` (numba), imported only
when a robust fit runs.

Why compiled: the rules are sequential per pixel (a pass refits, then judges the residuals
again: ~4.6 highlight passes and ~9 drops per pixel on the glossy benchmark scene), so a
vectorised numpy version pays per pass a few hundred ns of call overhead and memory traffic per
pixel for ~50 ns of arithmetic. Measured at 512² × 48 lights (``benchmarks.fit_throughput``):
the first whole-band numpy implementation ~185× a same-shape matrix product, its chunked
successor (NaN-as-unused, counting bisections for the medians, downdated normal equations)
~99×, the kernel 34× (33.8× against the chunked code's 98.1×, timed alternately in one run),
and since the kernel's rewrite of 2026-11-24 (passes on scalars, no array view per pixel,
counts 8 lanes at a time; see its docstring, bit-identical to the kernel before) 0.58× of
that: whole fits timed alternately with the kernel before it, 258 against 440 ms wall and 128
against 219 ms CPU (median of 15, load average 4.3–4.6, the matrix product 10.2 ms under that
load); 25.4× in docs/benchmarks.md's table of the same hour (load 4.5). The issue's target,
30×, is met (~20× expected at the load of the 34.3× table: 0.58 × 34.3). What remains is ~4.6
passes per pixel of ~70 ns each (residuals, counts, a downdate and a closed-form re-solve)
plus the block set-up.

The decisions are the original ones and the fits were bit-identical to the chunked numpy code
when it was replaced (compared old against new; the
kernel performs the same float32 and float64 operations in the same order, see its
docstring): the same float32 residuals compared with the same float32 thresholds
(``max(fl32(k * fl32(1.4826 * median)), floor)``, the lower median), the same darkest-first
choice, the same conditioning refusal. tests/reconstruct check the fit against a slow
per-pixel reference implementation.
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
                0.0 if rules.shadow_k is None else rules.shadow_k,  # 0: rule 4 off
                rules.floor,
                MAD_SCALE,
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


def warm_up() -> None:
    """Load the compiled kernel now (compile it, the first time on a machine: seconds).

    Why: an adaptive session fits after its fourth image; a first fit that imports numba
    (~0.4 s) or compiles the kernel (~6 s with no cache) would stall the session between two
    lights, and make its first decision look slow. A session calls this before the rig opens.
    """
    fit_robust_band(
        np.ones((3, 1), dtype=np.float32),
        np.ones(1, dtype=bool),
        np.eye(3),
        RobustRules(
            dark=0.0,
            saturation=None,
            highlight_k=2.0,
            floor=0.01,
            max_passes=1,
            cond_limit=100.0,
            shadow_k=2.0,
            shadow_min_kept=3,
            eps_b=0.0,
        ),
    )
