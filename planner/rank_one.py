"""Every one-light swap of the normals objective scored at once, by rank-one updates.

The exchange search (:mod:`rti_rig.planner.optimal`) asks, for one position of the layout, what
the cost becomes when its light is replaced by each candidate ``k``. Each pixel's information
matrix is then ``M = B + w l lᵀ``: the layout without that light (``B``, the same for every
candidate) plus one rank-one term (candidate direction ``l``, the pixel's weight ``w`` for it).
Sherman–Morrison gives ``M⁻¹ = B⁻¹ - s u uᵀ`` with ``u = B⁻¹ l``, ``s = w / (1 + w lᵀu)``, so the
terms of :class:`rti_rig.planner.objectives.NormalsObjective` reduce to quadratic and bilinear
forms in ``l`` (and the candidate's harmonics ``h``) whose per-pixel matrices are computed once
per scan — the (candidates × pixels) work becomes a few small matrix products and a handful
of element-wise operations instead of a 3×3 inverse and a 3×9 solve per candidate and pixel:

* variance: ``tr(P M⁻¹) = tr(P B⁻¹) - s lᵀ(B⁻¹PB⁻¹)l``;
* model bias: with ``G_B = B⁻¹R_B`` and ``D = G_B - G_all``, ``M⁻¹R = G_B + s u vᵀ`` where
  ``v = h - G_Bᵀl``, so ``‖P(M⁻¹R - G_all)‖² = ‖PD‖² + 2s uᵀPDv + s² ‖Pu‖² ‖v‖²``, each
  product expanded into forms in ``l`` and ``l ⊗ h``.

It is the same objective, not an approximation; the formulas need ``B⁻¹``, so a pixel whose
``B`` is singular or ill-conditioned (lit by fewer than three of the other lights) is left
to the caller's direct evaluation (``bad`` in :class:`ScanResult`).

The (candidates × pixels) passes may run in single precision on the pixels whose ``B`` is well
conditioned (:data:`SINGLE_CONDITIONED`): on this machine 3–5× faster than double (the
element-wise divisions most), with every candidate's cost within 1e-6 of the direct one (tested;
measured ~1e-7). The exchange search accepts a swap only on its double-precision cost, and a
proposal that cost rejects earns a double-precision, then a direct, re-scan.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: A pixel's ``B`` counts as invertible when det(B) exceeds this fraction of (tr(B)/3)³ (its
#: value were ``B`` a multiple of the identity): a condition number of at most ~10⁸, where the
#: double-precision updates keep ~8 digits. Others are evaluated directly.
WELL_CONDITIONED = 1e-8

#: Pixels whose ``B`` is at least this well conditioned (det/(tr/3)³, about 3.4 over the
#: condition number) are scanned in single precision when the caller allows it: there the
#: quadratic forms lose at most ~1e-5 of their value to rounding, the summed cost ~1e-7.
SINGLE_CONDITIONED = 1e-2

#: Regularisation added to the diagonal, as in the direct evaluation (it must match).
RIDGE = 1e-9


def quadratic_coefficients(d: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rows ``[x², 2xy, 2xz, y², 2yz, z²]`` per direction (K, 6): ``lᵀ S l`` is this row times
    the entries ``[S00, S01, S02, S11, S12, S22]`` of a symmetric ``S``."""
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    return np.stack([x * x, 2 * x * y, 2 * x * z, y * y, 2 * y * z, z * z], axis=1)


def _entries(s: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 6 entries (as in :func:`quadratic_coefficients`) of a batch of 3×3 (G, 3, 3),
    symmetrised: (6, G)."""
    return np.stack(
        [
            s[:, 0, 0],
            0.5 * (s[:, 0, 1] + s[:, 1, 0]),
            0.5 * (s[:, 0, 2] + s[:, 2, 0]),
            s[:, 1, 1],
            0.5 * (s[:, 1, 2] + s[:, 2, 1]),
            s[:, 2, 2],
        ]
    )


def _matrices(e: NDArray[np.float64]) -> NDArray[np.float64]:
    """Symmetric 3×3 matrices (G, 3, 3) from their 6 entries (6, G)."""
    a, b, c, d, f, g = e
    out = np.empty((e.shape[1], 3, 3), dtype=e.dtype)  # filled in place: 4× faster than stacks
    out[:, 0, 0], out[:, 0, 1], out[:, 0, 2] = a, b, c
    out[:, 1, 0], out[:, 1, 1], out[:, 1, 2] = b, d, f
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = c, f, g
    return out


def inverse_entries(
    base: NDArray[np.float64], threshold: float = WELL_CONDITIONED
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """``(B + ridge·I)⁻¹`` as 6 entries per pixel (6, P), and which pixels are conditioned
    (det(B) above ``threshold`` × (tr(B)/3)³; the entries of the others are not inverses)."""
    inv, ratio = _inverse_and_condition(base)
    return inv / np.where(ratio > threshold, ratio, 1.0), ratio > threshold


def _inverse_and_condition(
    base: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The adjugate of ``B + ridge·I`` divided by (tr/3)³ (6, P), and det/(tr/3)³ (P,) — 0 where
    det ≤ 1e-12 — so that the inverse is the first divided by the second."""
    a, b, c = base[0] + RIDGE, base[1], base[2]
    d, e, f = base[3] + RIDGE, base[4], base[5] + RIDGE
    c00, c11, c22 = d * f - e * e, a * f - c * c, a * d - b * b
    c01, c02, c12 = c * e - b * f, b * e - c * d, b * c - a * e
    det = a * c00 + b * c01 + c * c02
    scale = ((a + d + f) / 3.0) ** 3
    ratio = np.where(det > 1e-12, det / scale, 0.0)
    return np.stack([c00, c01, c02, c11, c12, c22]) / scale, ratio


def inverses(
    base: NDArray[np.float64], normals: NDArray[np.float64]
) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """The per-pixel start of :func:`scan` for the entries ``base`` (6, ..., P) of one or several
    ``B``: the entries of ``B⁻¹`` (6, ..., P; not inverses where ill-conditioned), the condition
    ratio (..., P), ``tr(P B⁻¹)`` (..., P) and the entries of ``B⁻¹PB⁻¹`` (6, ..., P). Every
    operation is element by element, so a batch gives each ``B`` the values it gets alone, bit
    for bit (tested); a batch costs far fewer calls than its ``B`` one by one."""
    inv6, ratio = _inverse_and_condition(base)
    inv6 = inv6 / np.where(ratio > WELL_CONDITIONED, ratio, 1.0)
    tr0, c6 = _projected_inverse(inv6, normals)
    return inv6, ratio, tr0, c6


@dataclass(frozen=True)
class ScanResult:
    """Weighted squared error (rad²) of every candidate over the well-conditioned pixels, and
    the pixels left to a direct evaluation (indices into the variance and bias pixels)."""

    err2: NDArray[np.float64]
    bad: NDArray[np.intp]
    bad_bias: NDArray[np.intp]


@dataclass(frozen=True)
class BiasTerms:
    """What the model-bias part needs: the layout's cross terms without the swapped light
    ``rb`` (3, Pb, 9), the all-light fit ``g_all`` (3, Pb, 9), the candidates' harmonics
    ``h`` (K, 9), their pixel weights and the prior's scale."""

    rb: NDArray[np.float64]
    g_all: NDArray[np.float64]
    h: NDArray[np.float64]
    wts: NDArray[np.float64]
    tau2: float
    #: the candidates' weights at the bias pixels (K, Pb); None: the first columns of ``w``
    w: NDArray[np.float64] | None = None
    #: ``[l ⊗ h, l6]`` (K, 33) and ``‖h‖²`` (K,) of these candidates, when the caller keeps
    #: them (they change only with the scored candidates); None: computed here
    forms_in: NDArray[np.float64] | None = None
    h2: NDArray[np.float64] | None = None


def candidate_forms(
    d: NDArray[np.float64], h: NDArray[np.float64], l6: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``[l ⊗ h, l6]`` (K, 33) and ``‖h‖²`` (K,): the bias scan's per-candidate inputs."""
    lh = (d[:, :, None] * h[:, None, :]).reshape(len(d), 27)
    return np.concatenate([lh, l6], axis=1), np.sum(h * h, axis=1)


def _projected_inverse(
    inv6: NDArray[np.float64], n: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``tr(P B⁻¹)`` (G,) and the entries (6, G) of ``B⁻¹ P B⁻¹ = B⁻² - u uᵀ`` (``u = B⁻¹n``,
    ``P = I - n nᵀ``) from the entries of ``B⁻¹`` (6, G): a few dozen operations on vectors,
    not three batched 3×3 products."""
    a, b, c, d, e, f = inv6
    x, y, z = n.T
    u0, u1, u2 = a * x + b * y + c * z, b * x + d * y + e * z, c * x + e * y + f * z
    tr0 = a + d + f - (x * u0 + y * u1 + z * u2)
    c6 = np.stack(
        [
            a * a + b * b + c * c - u0 * u0,
            a * b + b * d + c * e - u0 * u1,
            a * c + b * e + c * f - u0 * u2,
            b * b + d * d + e * e - u1 * u1,
            b * c + d * e + e * f - u1 * u2,
            c * c + e * e + f * f - u2 * u2,
        ]
    )
    return tr0, c6


def scan(
    base: NDArray[np.float64],
    w: NDArray[np.float64],
    d: NDArray[np.float64],
    l6: NDArray[np.float64],
    normals: NDArray[np.float64],
    wts: NDArray[np.float64],
    noise2: float,
    max_err2: float,
    bias: BiasTerms | None,
    *,
    rows: NDArray[np.intp] | None = None,
    w32: NDArray[np.float32] | None = None,
    below: float | None = None,
    w_max: float | None = None,
    l_max2: float | None = None,
    pre: tuple[NDArray, NDArray, NDArray, NDArray] | None = None,
    bias_pre: _BiasPrep | None = None,
) -> ScanResult:
    """Squared errors of ``B + w_k l_k l_kᵀ`` for every candidate ``k``.

    ``base`` (6, P): entries of ``B`` per pixel; ``w`` (K, P): each candidate's weight per
    pixel — or, with ``rows``, every candidate's (K_all, P) of which those rows are scored;
    ``d`` (K, 3) and ``l6 = quadratic_coefficients(d)``; ``normals`` (P, 3) and pixel weights
    ``wts`` (P,); the bias pixels are the first ``len(bias.wts)`` pixels.

    The (K, P) work is two products with ``l6`` and four element-wise passes; the pixel
    weights are folded into ``B⁻¹PB⁻¹`` before the product, so the weighted sum over pixels is
    a row-wise dot product. With ``w32`` (the scored candidates' weights in single precision,
    (K, P)), pixels whose ``B`` is well conditioned for it (:data:`SINGLE_CONDITIONED`) are
    scanned in single precision — several times faster, costs within ~1e-7 of the double
    precision ones (the caller confirms a swap on its exact cost) — and the others in double.

    ``below`` (squared error, rad²): only the candidates that could score under it are needed;
    the others may be returned as ``inf``. When every pixel is scanned in single precision
    (and the scan is large: :data:`BOUNDED_MIN_WORK`),
    the variance pass then runs only on the candidates whose lower bound
    (:func:`_variance_bound`) is under it, the others being proved not to — with the same
    values, bit for bit, as the full pass gives them (its products and passes are row by row;
    tested), so a search that asks which candidate scores least and whether it is under
    ``below`` gets the same answer. ``w_max``: the largest of ``w32``, ``l_max2`` the largest
    ``‖l‖²`` of ``d`` (or bounds on them: the caller may keep them). ``pre``: what
    :func:`inverses` gives for ``base`` (the caller may compute it for several bases at once);
    ``bias_pre``: what :func:`bias_prep_batch` gives for it, used when every bias pixel is
    well conditioned.
    """
    inv6, ratio, tr0, c6 = inverses(base, normals) if pre is None else pre
    good = ratio > WELL_CONDITIONED
    # the variance σ²(tr(P B⁻¹) - s q2) lies in [0, σ² tr(P B⁻¹)]: only where that bound
    # passes the cap does a pixel need clipping; elsewhere the weighted sum is taken directly
    capped = good & (noise2 * tr0 > max_err2)
    single = np.zeros_like(good)
    if w32 is not None:
        single = good & ~capped & (ratio > SINGLE_CONDITIONED)
    double = good & ~single
    c6w = c6 * wts
    err2 = noise2 * float(tr0[good] @ wts[good]) * np.ones(len(d))

    def weights(pix: NDArray[np.intp]) -> NDArray[np.float64]:
        return w[:, pix] if rows is None else w[np.ix_(rows, pix)]

    bounded = None
    if single.any():
        assert w32 is not None
        every = bool(single.all())
        sp = slice(None) if every else np.flatnonzero(single)
        f32 = np.float32
        args = (l6.astype(f32), inv6[:, sp].astype(f32), c6w[:, sp].astype(f32), w32[:, sp])
        if below is not None and every and len(d) >= 2 and w32.size >= BOUNDED_MIN_WORK:
            bounded = args  # the variance pass waits for the bias term (below)
        else:
            err2 -= noise2 * _reduction(*args)
    if double.any():
        dp = np.flatnonzero(double)
        cap = capped[dp]
        if cap.any():  # clipped pixel by pixel
            s = _reduction(l6, inv6[:, dp], c6[:, dp], weights(dp), per_pixel=True)
            var = np.clip(noise2 * (tr0[dp][None] - s), 0.0, max_err2)
            err2 += var @ wts[dp] - noise2 * float(tr0[dp] @ wts[dp])
        else:
            err2 -= noise2 * _reduction(l6, inv6[:, dp], c6w[:, dp], weights(dp))
    bad = np.flatnonzero(~good)
    bad_bias = np.zeros(0, dtype=np.intp)
    chain = None
    if bias is not None:
        nb = len(bias.wts)
        bad_bias = bad[bad < nb]
        gb = np.flatnonzero(good[:nb])
        if bias.w is None:
            wb = weights(gb)
        else:  # the same values; no gather when every bias pixel is kept
            wb = bias.w if len(gb) == bias.w.shape[1] else bias.w[:, gb]
        single_b = w32 is not None and bool(single[gb].all())
        if bias_pre is not None and len(gb) == nb:
            prep = bias_pre
        else:
            prep = _bias_prep(inv6[:, gb], c6[:, gb], normals[gb], bias, gb)
        if bias.forms_in is None or bias.h2 is None:
            forms_in, h2 = candidate_forms(d, bias.h, l6)
        else:
            forms_in, h2 = bias.forms_in, bias.h2
        wts_b = bias.wts[gb]
        chain = (prep, forms_in, h2, l6, wb, bias.tau2, wts_b, max_err2, single_b)
    if bounded is None:
        if chain is not None:
            err2 = err2 + _bias_chain(*chain)
        return ScanResult(err2, bad, bad_bias)
    assert below is not None
    # every pixel in single precision, none ill-conditioned: the passes run only on the
    # candidates whose lower bound leaves them a chance to score under ``below``
    if l_max2 is None:
        l_max2 = float(np.max(np.sum(d * d, axis=1)))
    if w_max is None:
        w_max = float(bounded[3].max(initial=0.0))
    l6f, inv32, c6w32, w_s = bounded
    bias_err2 = None
    bias_low = np.zeros(len(d))
    if chain is not None:
        prep, forms_in, h2, _, wb, tau2, wts_b, _, _ = chain
        low = _bias_bound(prep, forms_in, h2, wb, tau2, wts_b, max_err2, l_max2, w_max)
        if low is None:  # the cap may bind: the bias term of every candidate
            bias_err2 = low = _bias_chain(*chain)
        bias_low = low
    # the variance first with every weight at its largest (no (K, P) pass), then by the
    # product with the weights for the candidates that leaves (all of them when many do)
    lower = err2 - noise2 * _variance_bound(l6f, inv32, c6w32, None, l_max2, w_max) + bias_low
    maybe = np.flatnonzero(~(lower >= below))  # a NaN is kept: scored as in full
    if len(maybe):
        if 2 * len(maybe) > len(d):
            ub = _variance_bound(l6f, inv32, c6w32, w_s, l_max2, w_max)[maybe]
        else:
            ub = _variance_bound(l6f[maybe], inv32, c6w32, w_s[maybe], l_max2, w_max)
        lower[maybe] = err2[maybe] - noise2 * ub + bias_low[maybe]
        maybe = maybe[~(lower[maybe] >= below)]
    out = np.full(len(d), np.inf)
    if len(maybe) and chain is not None and bias_err2 is None:
        # the bias term itself where its bound left a chance, and the bound again
        pick = _two_rows(maybe)
        exact_b = _bias_chain(*chain, rows=pick)[: len(maybe)]
        keep = ~(lower[maybe] - bias_low[maybe] + exact_b >= below)
        maybe, exact_b = maybe[keep], exact_b[keep]
        bias_err2 = np.zeros(len(d))
        bias_err2[maybe] = exact_b
    if len(maybe):
        pick = _two_rows(maybe)
        l6f, inv32, c6w32, w_s = bounded
        part = err2[pick]
        part -= noise2 * _reduction(l6f[pick], inv32, c6w32, w_s[pick])
        if chain is not None:
            assert bias_err2 is not None
            part = part + bias_err2[pick]
        out[maybe] = part[: len(maybe)]
    return ScanResult(out, bad, bad_bias)


def _two_rows(rows: NDArray[np.intp]) -> NDArray[np.intp]:
    """``rows``, with another row after it when it has one: a product of one row is computed
    as a matrix-vector product, with other rounding than the same row among others."""
    return rows if len(rows) >= 2 else np.array([rows[0], 1 - min(int(rows[0]), 1)])


#: A scan bounds its candidates (``below``) from this many (candidate, pixel) pairs: below, its
#: few passes cost less than the bounds' fixed work (on this machine at ~200 000 pairs: the
#: shipped arm's 36 lights gained 10 %, its 9 lights and the 200-LED dome at 100 lost 8–10 %).
BOUNDED_MIN_WORK = 200_000

#: Relative margin on the variance bound's product (far above single precision's rounding of
#: it; the bound's own slack on the arm at 100 lights is ~3 % of the reduction).
BOUND_MARGIN = 1e-3


def _variance_bound(
    l6: NDArray[np.float32],
    inv6: NDArray[np.float32],
    c6: NDArray[np.float32],
    w: NDArray[np.float32] | None,
    l_max2: float = 1.0,
    w_max: float = 1.0,
) -> NDArray[np.float64]:
    """An upper bound (K,) on what :func:`_reduction` returns for these arguments (single
    precision, every pixel), from one (K, P)(P, 6) product instead of its passes — or, with
    ``w`` None, from ``w ≤ w_max`` alone (no (K, P) work; looser where a light is shadowed).

    Each term ``s q`` has ``s = w / (1 + w lᵀB⁻¹l) ≤ w`` (``B⁻¹`` positive definite) and
    ``q = lᵀCl ≥ 0`` (``C = B⁻¹PB⁻¹`` positive semi-definite), so ``Σ_p s q ≤ lᵀ(Σ_p w_p C_p)l``.
    The margin covers both computations' rounding: relative :data:`BOUND_MARGIN`, plus
    (P + 16)·2⁻²³ of ``Σ|C|`` twice (each sum of P terms with |l6| ≤ ‖l‖² ≤ ``l_max2``,
    0 ≤ s ≤ w ≤ max(1, ``w_max``); the (K, P)(P, 6) product and the reduction's passes).
    """
    if w is None:
        x = w_max * c6.astype(np.float64).sum(axis=1)[None]  # (1, 6)
    else:
        x = (w @ c6.T).astype(np.float64)  # Σ_p w_kp C_p  (K, 6)
    ub = np.einsum("kj,kj->k", l6.astype(np.float64), np.broadcast_to(x, l6.shape))
    slack = 2.0 * (c6.shape[1] + 16) * 2.0**-23 * float(np.abs(c6).astype(np.float64).sum())
    slack *= max(l_max2, 1.0) * max(w_max, 1.0)
    return np.maximum(ub, 0.0) * (1.0 + BOUND_MARGIN) + slack


def _reduction(
    l6: NDArray, inv6: NDArray, c6: NDArray, w: NDArray, per_pixel: bool = False
) -> NDArray:
    """``Σ_p s_kp lᵀC_pl`` per candidate (K,), ``s = w / (1 + w lᵀB⁻¹l)``, for the entries of
    ``B⁻¹`` and of ``C`` (6, G) (``B⁻¹PB⁻¹``, pixel weights folded in); ``per_pixel``: the
    terms themselves (K, G). In the dtype of the arguments."""
    s = l6 @ inv6  # lᵀ B⁻¹ l  (K, G)
    q2 = l6 @ c6
    s *= w
    s += 1.0
    np.divide(w, s, out=s)  # s = w / (1 + w lᵀ B⁻¹ l)
    if per_pixel:
        q2 *= s
        return q2
    return np.einsum("kp,kp->k", s, q2).astype(np.float64)


@dataclass(frozen=True)
class _BiasPrep:
    """The bias term's per-pixel coefficients of one scan (its well-conditioned bias pixels):
    ``c0 = ‖PD‖²`` (Gb,), the forms' coefficients for ``[l ⊗ h, l6]`` (33, 2Gb), those of
    ``lᵀB⁻¹l`` and ``lᵀB⁻¹PB⁻¹l`` for ``l6`` (6, 2Gb), ``tr B⁻¹`` (Gb,) and ``‖G_B‖_F`` (Gb,)."""

    c0: NDArray[np.float64]
    coef: NDArray[np.float64]
    quad: NDArray[np.float64]
    trace: NDArray[np.float64]
    g_norm: NDArray[np.float64]


def _bias_prep(
    inv_b: NDArray[np.float64],
    qc6: NDArray[np.float64],
    n: NDArray[np.float64],
    bias: BiasTerms,
    gb: NDArray[np.intp],
) -> _BiasPrep:
    """The per-pixel part of the bias scan over the bias pixels ``gb``: their entries of
    ``B⁻¹`` and ``B⁻¹PB⁻¹`` (6, Gb) and normals (Gb, 3)."""
    bi = _matrices(inv_b)  # (Gb, 3, 3)
    pr = np.eye(3)[None] - n[:, :, None] * n[:, None, :]
    rb = np.transpose(bias.rb[:, gb], (1, 0, 2))  # (Gb, 3, 9)
    ga = np.transpose(bias.g_all[:, gb], (1, 0, 2))
    gbm = bi @ rb  # G_B = B⁻¹ R_B
    pdm = pr @ (gbm - ga)  # P D
    c0 = np.sum(pdm * pdm, axis=(1, 2))  # ‖P D‖²
    f = bi @ pdm  # B⁻¹ P D, so uᵀ P D v = lᵀ F (h - G_Bᵀ l)
    m = len(gb)
    gbt = np.transpose(gbm, (0, 2, 1))
    # the forms in l the bias needs: lᵀFh - lᵀFG_Bᵀl and -2 lᵀG_Bh + lᵀG_BG_Bᵀl from one
    # product of [l ⊗ h, l6] (K, 33); lᵀB⁻¹l and lᵀB⁻¹PB⁻¹l from one product of l6
    coef = np.empty((33, 2 * m))
    coef[:27, :m] = f.reshape(m, 27).T
    coef[:27, m:] = -2.0 * gbm.reshape(m, 27).T
    coef[27:, :m] = -_entries(f @ gbt)
    coef[27:, m:] = _entries(gbm @ gbt)
    quad = np.concatenate([inv_b, qc6], axis=1)
    trace = inv_b[0] + inv_b[3] + inv_b[5]
    return _BiasPrep(c0, coef, quad, trace, np.sqrt(np.sum(gbm * gbm, axis=(1, 2))))


def bias_prep_batch(
    inv_b: NDArray[np.float64],
    qc6: NDArray[np.float64],
    n: NDArray[np.float64],
    rb: NDArray[np.float64],
    g_all: NDArray[np.float64],
) -> list[_BiasPrep]:
    """:func:`_bias_prep` for several layouts at once: entries of ``B⁻¹`` and ``B⁻¹PB⁻¹``
    (6, B, Gb), normals (Gb, 3), cross terms (3, B, Gb, 9) and the all-light fit (3, Gb, 9) of
    the bias pixels kept. The same operations on a leading axis — each layout's values bit for
    bit (tested) — in a tenth of the calls."""
    nb, m = inv_b.shape[1], inv_b.shape[2]
    bi = np.empty((nb, m, 3, 3))
    a, b, c, d, f_, g = inv_b
    bi[..., 0, 0], bi[..., 0, 1], bi[..., 0, 2] = a, b, c
    bi[..., 1, 0], bi[..., 1, 1], bi[..., 1, 2] = b, d, f_
    bi[..., 2, 0], bi[..., 2, 1], bi[..., 2, 2] = c, f_, g
    pr = np.eye(3)[None] - n[:, :, None] * n[:, None, :]
    rbm = np.transpose(rb, (1, 2, 0, 3))  # (B, Gb, 3, 9)
    ga = np.transpose(g_all, (1, 0, 2))
    gbm = bi @ rbm
    pdm = pr @ (gbm - ga)
    c0 = np.sum(pdm * pdm, axis=(2, 3))
    fm = bi @ pdm
    gbt = np.transpose(gbm, (0, 1, 3, 2))
    fg, gg = fm @ gbt, gbm @ gbt
    quad = np.concatenate([inv_b, qc6], axis=2)
    trace = inv_b[0] + inv_b[3] + inv_b[5]
    g_norm = np.sqrt(np.sum(gbm * gbm, axis=(2, 3)))
    out = []
    for j in range(nb):
        coef = np.empty((33, 2 * m))
        coef[:27, :m] = fm[j].reshape(m, 27).T
        coef[:27, m:] = -2.0 * gbm[j].reshape(m, 27).T
        coef[27:, :m] = -_entries(fg[j])
        coef[27:, m:] = _entries(gg[j])
        out.append(_BiasPrep(c0[j], coef, quad[:, j], trace[j], g_norm[j]))
    return out


def _bias_chain(
    prep: _BiasPrep,
    forms_in: NDArray[np.float64],
    h2: NDArray[np.float64],
    l6: NDArray[np.float64],
    wb: NDArray[np.float64],
    tau2: float,
    wts_b: NDArray[np.float64],
    max_err2: float,
    single: bool,
    rows: NDArray[np.intp] | None = None,
) -> NDArray[np.float64]:
    """The bias term (K,) of the candidates whose ``[l ⊗ h, l6]``, ``‖h‖²``, ``l6`` and weights
    at the bias pixels are given; the (K, Gb) work in single precision when ``single``.

    ``rows`` (at least two): only those candidates' terms, with the values the whole call
    gives them bit for bit — the products whose rounding depends on the number of rows (the
    33-term forms, the sum over pixels) still run over every row, the element-wise passes and
    the 6-term product (row by row: tested) only over ``rows``."""
    dt = np.float32 if single else np.float64
    m = len(prep.c0)
    forms = forms_in.astype(dt, copy=False) @ prep.coef.astype(dt, copy=False)
    if rows is None:
        quad = l6.astype(dt, copy=False) @ prep.quad.astype(dt, copy=False)
        w = wb.astype(dt, copy=False)
        h2_ = h2
    else:
        forms = forms[rows]
        quad = l6[rows].astype(dt, copy=False) @ prep.quad.astype(dt, copy=False)
        w = wb[rows].astype(dt, copy=False)
        h2_ = h2[rows]
    cross, spread, sb, qb = forms[:, :m], forms[:, m:], quad[:, :m], quad[:, m:]
    sb *= w
    sb += 1.0
    np.divide(w, sb, out=sb)  # s = w / (1 + w lᵀ B⁻¹ l)
    # ‖P(M⁻¹R - G_all)‖² = c0 + s (2 cross + s qb (‖h‖² + spread))
    spread += h2_.astype(dt, copy=False)[:, None]
    spread *= qb
    spread *= sb
    cross *= 2.0
    cross += spread
    cross *= sb
    tang = cross + prep.c0.astype(dt)[None]
    tang *= tau2
    if rows is None:
        return (np.clip(tang, 0.0, max_err2) @ wts_b.astype(dt)).astype(np.float64)
    every = np.zeros((len(forms_in), m), dtype=dt)
    every[rows] = np.clip(tang, 0.0, max_err2)
    return (every @ wts_b.astype(dt)).astype(np.float64)[rows]


def _bias_bound(
    prep: _BiasPrep,
    forms_in: NDArray[np.float64],
    h2: NDArray[np.float64],
    wb: NDArray[np.float64],
    tau2: float,
    wts_b: NDArray[np.float64],
    max_err2: float,
    l_max2: float,
    w_max: float,
) -> NDArray[np.float64] | None:
    """A lower bound (K,) on what :func:`_bias_chain` returns for these candidates, from one
    (K, Gb)(Gb, 33) product instead of its passes; None when the cap could bind.

    Per pixel the term is ``τ² ‖PD + s P u vᵀ‖²`` (``u = B⁻¹l``, ``v = h - G_Bᵀl``,
    ``s = w / (1 + w a)``, ``a = lᵀB⁻¹l``) ``= τ² (c0 + 2sX + s²Y)`` with ``X = uᵀPDv`` and
    ``Y = ‖Pu‖²‖v‖² ≥ 0``. Since ``|X| ≤ √(c0 Y)`` and ``w - s = s·wa``,
    ``2sX = 2wX - 2(w - s)X ≥ 2wX - s²Y - (wa)² c0``, so the term is at least
    ``τ² (c0 (1 - w²a²) + 2wX)``, with ``a ≤ tr B⁻¹ ‖l‖²``: linear in ``X`` (itself linear in
    ``[l ⊗ h, l6]``) and in ``w²``, so summed over pixels by products. The cap
    (``max_err2``) is checked not to bind from ``‖PD + s P u vᵀ‖ ≤ √c0 + w ‖B⁻¹‖ ‖l‖ (‖h‖ +
    ‖G_B‖ ‖l‖)`` (:func:`_bias_reach`); the margin (:data:`BIAS_MARGIN` of that bound's
    weighted sum) covers single precision's rounding of the chain, whose terms it also bounds.
    """
    m = len(prep.c0)
    t_max = _bias_reach(prep, h2, l_max2, w_max)
    if not float(tau2 * t_max.max(initial=0.0)) < max_err2:
        return None
    lin = np.einsum("kj,kj->k", forms_in, wb @ (prep.coef[:, :m] * wts_b).T)  # Σ_p wts w X
    a_max2 = (prep.trace * l_max2) ** 2  # (wa)² ≤ w² (tr B⁻¹ ‖l‖²)²
    lower = float(prep.c0 @ wts_b) - (wb * wb) @ (wts_b * prep.c0 * a_max2) + 2.0 * lin
    return tau2 * lower - BIAS_MARGIN * tau2 * float(t_max @ wts_b)


#: Margin of the bias term's lower bounds, as a fraction of :func:`_bias_reach`'s weighted sum:
#: single precision rounds each of the chain's ~40 operations by at most 2⁻²⁴ of a term that
#: reach bounds (~2.4e-6 of it in all), 40× less than this.
BIAS_MARGIN = 1e-4


def _bias_reach(
    prep: _BiasPrep, h2: NDArray[np.float64], l_max2: float, w_max: float
) -> NDArray[np.float64]:
    """Per bias pixel, a bound (Gb,) on ``‖PD + s P u vᵀ‖²`` for every candidate and on each
    term of its expansion: ``(√c0 + w ‖B⁻¹‖ ‖l‖ (‖h‖ + ‖G_B‖ ‖l‖))²``, with ``tr B⁻¹`` for
    ``‖B⁻¹‖`` and ``‖G_B‖_F`` for ``‖G_B‖``."""
    l_max = float(np.sqrt(l_max2))
    h_max = float(np.sqrt(h2.max(initial=0.0)))
    reach = w_max * prep.trace * l_max * (h_max + prep.g_norm * l_max)
    return (np.sqrt(prep.c0) + reach) ** 2
