"""Per-pixel least squares of photometric stereo through its 3 × 3 normal equations.

Used by least-squares photometric stereo's per-pixel path and by PTM's normal estimate:
``sum_k w_k l_k l_k^T`` and ``sum_k w_k I_k l_k`` per pixel, solved in closed form for millions
of pixels at once. The robust fit's compiled kernel (:mod:`rti_rig.reconstruct.robust_kernel`)
performs the same solve and conditioning test term for term, pixel by pixel.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Index pairs of the 6 distinct entries of a symmetric 3 × 3 matrix, in the order used below.
_SYM6 = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def light_products(lights: NDArray[np.float64]) -> NDArray[np.float64]:
    """``l_i l_j`` of each light for the 6 distinct entries of ``l l^T``: (N, 6)."""
    return np.stack([lights[:, i] * lights[:, j] for i, j in _SYM6], axis=1)


def normal_equations(
    g: NDArray[np.float32], w: NDArray[np.bool_], lights: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """``sum_k w_k l_k l_k^T`` (6, P) in float64 (near-singular subsets must be detected),
    ``sum_k w_k I_k l_k`` (3, P) and the count of used observations (P,), for pixel-major
    ``g``, ``w`` (P, N)."""
    m = np.ascontiguousarray((w.astype(np.float64) @ light_products(lights)).T)
    rhs = (np.where(w, g, np.float32(0.0)) @ lights.astype(np.float32)).T.astype(np.float64)
    return m, rhs, w.sum(axis=1)


#: Margin of the eigenvalue-free conditioning test: a pixel whose bound on the eigenvalue ratio is
#: within this fraction of the limit is accepted without its eigenvalues (the bound is exact
#: arithmetic; rounding of either computation is ~1e-12 of the ratio, far inside the margin).
_BOUND_MARGIN = 0.99


def _eigen_ratio_ok(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    c: NDArray[np.float64],
    d: NDArray[np.float64],
    e: NDArray[np.float64],
    f: NDArray[np.float64],
    det: NDArray[np.float64],
    count: NDArray[Any],
    cond_limit: float,
) -> NDArray[np.bool_]:
    """Eigenvalue ratio within ``cond_limit**2`` by the trigonometric eigenvalues (Smith 1961),
    at least 3 observations and a non-zero determinant."""
    q = (a + d + f) / 3.0
    p1 = b * b + c * c + e * e
    aq, dq, fq = a - q, d - q, f - q
    p2 = aq * aq + dq * dq + fq * fq + 2.0 * p1
    p = np.sqrt(np.maximum(p2, 0.0) / 6.0)
    pos = p > 0
    ps = np.where(pos, p, 1.0)
    ba, bd, bf = aq / ps, dq / ps, fq / ps
    bb, bc, be = b / ps, c / ps, e / ps
    r = (ba * (bd * bf - be * be) - bb * (bb * bf - be * bc) + bc * (bb * be - bd * bc)) / 2.0
    phi = np.arccos(np.clip(r, -1.0, 1.0)) / 3.0
    e1 = np.where(pos, q + 2.0 * p * np.cos(phi), q)
    e3 = np.where(pos, q + 2.0 * p * np.cos(phi + 2.0 * np.pi / 3.0), q)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(e3 > e1 * 1e-14, e1 / e3, np.inf)
    ok = np.isfinite(ratio) & (np.abs(det) > 0)
    return ok & (count >= 3) & (ratio <= cond_limit**2)


def solve_normal_equations(
    m: NDArray[np.float64],
    rhs: NDArray[np.float64],
    count: NDArray[Any],
    cond_limit: float,
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Solve the symmetric PSD systems ``m`` (6, P) ``b = rhs`` (3, P) in closed form.

    Adjugate, component by component on contiguous rows: ~20× faster than batched LAPACK for
    millions of 3 × 3 systems. Returns b (P, 3) (zero where unsolvable) and solvable (P,): at
    least 3 observations and an eigenvalue ratio within ``cond_limit**2`` (the condition number
    of the light subset within ``cond_limit``).

    The ratio test needs the eigenvalues (trigonometric, Smith 1961: an arccos and two cosines
    per pixel, most of the solve's cost) only where a cheap bound cannot decide: with
    ``e1 >= e2 >= e3 > 0``, ``e1 + e2 <= trace`` gives ``e1 / e3 = e1**2 e2 / det <=
    4 trace**3 / (27 det)``; a pixel within the limit by that bound is well-conditioned.
    """
    a, b, c, d, e, f = m
    co_a = d * f - e * e
    co_b = c * e - b * f
    co_c = b * e - c * d
    co_d = a * f - c * c
    co_e = b * c - a * e
    co_f = a * d - b * b
    det = a * co_a + b * co_b + c * co_c
    tr = a + d + f
    with np.errstate(invalid="ignore", over="ignore"):
        ok = (4.0 / 27.0) * tr * tr * tr <= (_BOUND_MARGIN * cond_limit**2) * det
    ok &= (count >= 3) & (det > 0)
    unsure = np.flatnonzero(~ok)
    if unsure.size:
        ok[unsure] = _eigen_ratio_ok(
            *(x[unsure] for x in (a, b, c, d, e, f, det)), count[unsure], cond_limit
        )
    with np.errstate(divide="ignore"):
        inv_det = 1.0 / det
    inv_det[~ok] = 0.0
    r0, r1, r2 = rhs
    out = np.empty((m.shape[1], 3))
    o0, o1, o2 = out.T
    o0[:] = (co_a * r0 + co_b * r1 + co_c * r2) * inv_det
    o1[:] = (co_b * r0 + co_d * r1 + co_e * r2) * inv_det
    o2[:] = (co_c * r0 + co_e * r1 + co_f * r2) * inv_det
    return out, ok


def solve_weighted(
    g: NDArray[np.float32], w: NDArray[np.bool_], lights: NDArray[np.float64], cond_limit: float
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Least squares per pixel on its used observations.

    ``g`` and ``w`` are pixel-major (P, N) so that gathering a subset of pixels is contiguous.
    Returns b (P, 3) and solvable (P,): at least 3 observations and a light subset whose
    condition number is within ``cond_limit``.
    """
    m, rhs, count = normal_equations(g, w, lights)
    return solve_normal_equations(m, rhs, count, cond_limit)
