"""The compiled per-pixel loop of robust photometric stereo (numba).

Imported only by :func:`rti_rig.reconstruct.robust_ps.fit_robust_band`, when a robust fit runs:
numba and llvmlite cost tens of MB of memory and a fraction of a second to import, which a
least-squares fit (whose memory is at relight's limit) must not pay.

Pixels are taken in blocks of :data:`BLOCK_PIXELS`: the block's normal equations are summed
across its pixels in SIMD lanes, straight from the band's light-major rows; then each pixel
runs its passes alone (rules 3 and 4 of :mod:`rti_rig.reconstruct.photometric_stereo`) on a
pixel-major copy of its values, and its outputs are computed at once. Every arithmetic step is
the one the former numpy implementation (chunked, BLAS products) performed, in the same order,
so the fits are bit-identical to it (measured on the benchmark scene and the reference tests):

* float32 products accumulate with fused multiply-adds, one term after another in light order,
  as OpenBLAS's sgemm does (checked bit for bit): the residuals ``g - L b`` (K = 3), the
  initial ``sum I l`` (K = N), the colour projections, the RMS residual's prediction.
* float64 sums (``sum l l^T``, the downdates by the dropped terms) run in light order from zero.
* The 3 × 3 solve and its conditioning test are those of
  :func:`rti_rig.reconstruct.normal_equations.solve_normal_equations`, term for term (numba
  does not contract a product and a sum into a fused one without ``fastmath``). Only the
  trigonometric eigenvalues (needed where the cheap bound cannot decide) may differ from
  numpy's in the last bit, which matters only for a ratio within rounding of ``cond_limit``.

No median is computed. The threshold is the floor whenever more than half of the used
|residuals| are at most the cut (:func:`rti_rig.reconstruct.robust_ps.threshold_cut`);
otherwise a residual ``x`` exceeds ``max(fl32(k * fl32(1.4826 * median)), floor)`` iff it
exceeds the floor and more than half of the used |residuals| lie below the least float32
median whose threshold reaches ``x`` (a count; :func:`_exceeds`). A sort or a selection of
~48 values costs more in mispredicted branches than the few counts that decide.

No ``parallel=True``: a band runs on one core (the benchmark's ratio is against a one-thread
product; callers that want cores fit bands in threads, which ``nogil`` allows).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.extending import intrinsic

from rti_rig.reconstruct.robust_ps import MAD_SCALE

#: Margin of the eigenvalue-free conditioning test (as in ``normal_equations``).
_BOUND_MARGIN = 0.99
#: Pixels per block: the block's work arrays (~30 KB at 48 lights) stay in the L1/L2 cache.
BLOCK_PIXELS = 128
#: The median absolute deviation's scale to a Gaussian sigma, as float32 in the thresholds.
_MAD32 = np.float32(MAD_SCALE)


@intrinsic
def _fma32(typingctx, a, b, c):  # type: ignore[no-untyped-def]
    """``fl32(a * b + c)`` rounded once (LLVM's fma: one instruction, vectorisable)."""
    sig = types.float32(types.float32, types.float32, types.float32)

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        return builder.fma(*args)

    return sig, codegen


@njit(cache=True, nogil=True)
def _eigen_ratio_ok(a, b, c, d, e, f, det, count, cond2):  # type: ignore[no-untyped-def]
    """``normal_equations._eigen_ratio_ok`` for one pixel (trigonometric eigenvalues)."""
    q = (a + d + f) / 3.0
    p1 = b * b + c * c + e * e
    aq, dq, fq = a - q, d - q, f - q
    p2 = aq * aq + dq * dq + fq * fq + 2.0 * p1
    p = math.sqrt(max(p2, 0.0) / 6.0)
    if p > 0:
        ba, bd, bf = aq / p, dq / p, fq / p
        bb, bc, be = b / p, c / p, e / p
        r = (ba * (bd * bf - be * be) - bb * (bb * bf - be * bc) + bc * (bb * be - bd * bc)) / 2.0
        phi = math.acos(min(max(r, -1.0), 1.0)) / 3.0
        e1 = q + 2.0 * p * math.cos(phi)
        e3 = q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    else:
        e1 = q
        e3 = q
    if not e3 > e1 * 1e-14:
        return False
    ratio = e1 / e3
    if not (math.isfinite(ratio) and abs(det) > 0):
        return False
    return count >= 3 and ratio <= cond2


@njit(cache=True, nogil=True, inline="always")
def _solve(m, rhs, count, cond2, b):  # type: ignore[no-untyped-def]
    """Solve ``m`` (6,) ``b = rhs`` (3,) into ``b`` as ``solve_normal_equations`` does (zero
    where unsolvable; ``cond2``: ``cond_limit**2``); returns whether the pixel is solvable."""
    a, bb, c, d, e, f = m[0], m[1], m[2], m[3], m[4], m[5]
    co_a = d * f - e * e
    co_b = c * e - bb * f
    co_c = bb * e - c * d
    co_d = a * f - c * c
    co_e = bb * c - a * e
    co_f = a * d - bb * bb
    det = a * co_a + bb * co_b + c * co_c
    tr = a + d + f
    ok = (4.0 / 27.0) * tr * tr * tr <= (_BOUND_MARGIN * cond2) * det
    ok = ok and count >= 3 and det > 0
    if not ok:
        ok = _eigen_ratio_ok(a, bb, c, d, e, f, det, count, cond2)
    inv_det = 1.0 / det if ok else 0.0
    b[0] = (co_a * rhs[0] + co_b * rhs[1] + co_c * rhs[2]) * inv_det
    b[1] = (co_b * rhs[0] + co_d * rhs[1] + co_e * rhs[2]) * inv_det
    b[2] = (co_c * rhs[0] + co_e * rhs[1] + co_f * rhs[2]) * inv_det
    return ok


@njit(cache=True, nogil=True, inline="always")
def _scaled(m, scale):  # type: ignore[no-untyped-def]
    """``fl32(scale * fl32(1.4826 * m))``: a median's threshold before the floor."""
    return scale * (_MAD32 * m)


@njit(cache=True, nogil=True, inline="always")
def _median_bound(x, scale, inv, bits):  # type: ignore[no-untyped-def]
    """The least float32 ``m >= 0`` whose threshold ``_scaled(m)`` reaches ``x`` (+inf if
    none): a residual ``x`` exceeds the threshold of a median iff the median is below it.
    From ``x * inv`` (``inv = 1 / (scale * 1.4826)``), corrected by float32 steps; bisection
    over the bit patterns (monotone for non-negative floats) if that does not settle.
    ``bits``: a 1-element float32 scratch array (its int32 view steps a float by one)."""
    inf = np.float32(np.inf)
    if not _scaled(inf, scale) >= x:  # a zero scale (or x = inf): no median reaches it
        return inf
    zero = np.float32(0.0)
    if _scaled(zero, scale) >= x:
        return zero
    ints = bits.view(np.int32)
    bits[0] = np.float32(np.float64(x) * inv)
    for _ in range(8):  # sought: _scaled(m) >= x > _scaled(the float below m)
        m = bits[0]
        if _scaled(m, scale) >= x:  # m > 0 here
            ints[0] -= 1
            if _scaled(bits[0], scale) < x:
                return m
        else:
            ints[0] += 1
    lo, hi = 0, 0x7F800000  # 0.0 (below x) and +inf (reaches x)
    while hi - lo > 1:
        ints[0] = (lo + hi) // 2
        if _scaled(bits[0], scale) >= x:
            hi = ints[0]
        else:
            lo = ints[0]
    ints[0] = hi
    return bits[0]


@njit(cache=True, nogil=True, inline="always")
def _exceeds(x, ra, n, scale, inv, floor, bits):  # type: ignore[no-untyped-def]
    """Whether ``x > max(fl32(scale * fl32(1.4826 * median)), floor)`` for the lower median
    (index ``(n - 1) // 2`` sorted) of the ``n`` used |residuals| (``ra``: +inf where unused)
    without the median, which is below the bound of ``x`` iff more than ``(n - 1) // 2`` used
    values are."""
    if not x > floor:
        return False
    t = _median_bound(x, scale, inv, bits)
    below = 0
    for k in range(ra.shape[0]):
        below += ra[k] < t
    return below > (n - 1) // 2


@njit(cache=True, nogil=True, inline="always")
def _residuals(gv, lx, ly, lz, b, r):  # type: ignore[no-untyped-def]
    """``r = gv - fl32(L b)`` for every light (float32, as BLAS; unused ones too, to be
    masked by the caller: a loop without branches runs in SIMD lanes)."""
    b0, b1, b2 = np.float32(b[0]), np.float32(b[1]), np.float32(b[2])
    for k in range(gv.shape[0]):
        r[k] = gv[k] - _fma32(lz[k], b2, _fma32(ly[k], b1, lx[k] * b0))


@njit(cache=True, nogil=True, inline="always")
def _downdate(m, rhs, k, value, ll6, lights):  # type: ignore[no-untyped-def]
    """Add observation ``k`` (``value``) to the sums ``m``, ``rhs`` (to be subtracted)."""
    for j in range(6):
        m[j] += ll6[k, j]
    v64 = np.float64(value)
    for j in range(3):
        rhs[j] += v64 * lights[k, j]


@njit(cache=True, nogil=True, inline="always")
def _pixel_passes(  # type: ignore[no-untyped-def]
    gv, used, m, rhs, b, n, lx, ly, lz, ll6, lights, rules_f32, max_passes, shadow_min_kept,
    cond2, r, ra, cand, bits, mt, rhst, bt,
):
    """Rules 3 and 4 for one solvable pixel: its values ``gv`` (N,), ``used`` (N,) mask,
    normal equations ``m``, ``rhs`` and fit ``b`` (``n`` used), all updated in place; returns
    the final count and solvability. ``rules_f32``: highlight_k, its cut, shadow_k (0: off),
    floor; the last eight arguments are scratch."""
    highlight_k, cut, shadow_k, floor = rules_f32[0], rules_f32[1], rules_f32[2], rules_f32[3]
    # first guesses of the medians' bounds (any finite value will do: see _median_bound)
    inv_h = 1.0 / max(np.float64(highlight_k) * np.float64(_MAD32), 1e-30)
    inv_s = 1.0 / max(np.float64(shadow_k) * np.float64(_MAD32), 1e-30)
    n_img = gv.shape[0]
    inf = np.float32(np.inf)
    # rule 3: highlights, every used residual above the threshold per pass, then a refit
    for _ in range(max_passes):
        _residuals(gv, lx, ly, lz, b, r)
        over = 0
        small = 0
        for k in range(n_img):
            over += used[k] & (r[k] > floor)
            ra[k] = abs(r[k]) if used[k] else inf
            small += ra[k] <= cut
        if over == 0:
            break
        # the threshold is the floor when the median is at most the cut; else the residuals
        # above the floor are judged by _exceeds, monotone in the residual: a binary search
        # over them, sorted, finds the least one dropped
        x_cut = -inf
        if small <= (n - 1) // 2:
            nc = 0
            for k in range(n_img):
                if used[k] and r[k] > floor:
                    x = r[k]
                    i = nc
                    while i > 0 and cand[i - 1] > x:
                        cand[i] = cand[i - 1]
                        i -= 1
                    cand[i] = x
                    nc += 1
            if not _exceeds(cand[0], ra, n, highlight_k, inv_h, floor, bits):
                if not _exceeds(cand[nc - 1], ra, n, highlight_k, inv_h, floor, bits):
                    break
                lo, hi = 0, nc - 1  # cand[lo] kept, cand[hi] dropped
                while hi - lo > 1:
                    mid = (lo + hi) // 2
                    if _exceeds(cand[mid], ra, n, highlight_k, inv_h, floor, bits):
                        hi = mid
                    else:
                        lo = mid
                x_cut = cand[hi]
        mt[:] = 0.0
        rhst[:] = 0.0
        dropped = 0
        for k in range(n_img):
            if used[k] and r[k] > floor and r[k] >= x_cut:
                used[k] = False
                dropped += 1
                _downdate(mt, rhst, k, gv[k], ll6, lights)
        for j in range(6):
            m[j] -= mt[j]
        for j in range(3):
            rhs[j] -= rhst[j]
        n -= dropped
        if not _solve(m, rhs, n, cond2, b):
            return n, False

    # rule 4: partial shadows, the darkest observation per pass
    if shadow_k <= 0:
        return n, True
    for _ in range(max_passes):
        if n <= shadow_min_kept:
            break
        _residuals(gv, lx, ly, lz, b, r)
        worst = -1
        low = np.float32(np.inf)
        for k in range(n_img):
            if used[k] and r[k] < low:  # the first at the minimum, as argmin picks it
                low, worst = r[k], k
        for k in range(n_img):
            ra[k] = abs(r[k]) if used[k] else inf
        if not _exceeds(-low, ra, n, shadow_k, inv_s, floor, bits):
            break
        mt[:] = 0.0
        rhst[:] = 0.0
        _downdate(mt, rhst, worst, gv[worst], ll6, lights)
        for j in range(6):
            mt[j] = m[j] - mt[j]
        for j in range(3):
            rhst[j] = rhs[j] - rhst[j]
        if not _solve(mt, rhst, n - 1, cond2, bt):
            break  # a drop that leaves the pixel unsolvable is not made
        used[worst] = False
        n -= 1
        m[:] = mt
        rhs[:] = rhst
        b[:] = bt
    return n, True


@njit(cache=True, nogil=True)
def fit_pixels(  # type: ignore[no-untyped-def]
    g, inside, colour, lights, dark, sat, rules_f32, max_passes, shadow_min_kept, cond2,
    eps_b, normals, albedo, rms, count_out, ok_out,
):
    """The robust fit of every pixel of ``g`` (N, P) float32 (C order; NaN, infinite and
    saturated values are not used), ``inside`` (P,) the mask, ``colour`` (N, P, C) float32
    (unusable values zeroed) or an empty array for grey albedo from the normal equations,
    ``lights`` (N, 3) float64; ``dark``, ``sat`` and ``rules_f32`` (see ``_pixel_passes``)
    float32. Writes ``normals`` (P, 3), ``albedo`` (P, C), ``rms`` (P,), ``count_out`` (P,)
    and ``ok_out`` (P,).
    """
    n_img, p_total = g.shape
    grey = colour.shape[0] == 0
    channels = albedo.shape[1]
    l32 = lights.astype(np.float32)
    lx, ly, lz = l32[:, 0].copy(), l32[:, 1].copy(), l32[:, 2].copy()
    ll6 = np.empty((n_img, 6))
    for k in range(n_img):
        x, y, z = lights[k, 0], lights[k, 1], lights[k, 2]
        ll6[k, 0], ll6[k, 1], ll6[k, 2] = x * x, x * y, x * z
        ll6[k, 3], ll6[k, 4], ll6[k, 5] = y * y, y * z, z * z
    blk = BLOCK_PIXELS
    # per block, across its pixels: the normal equations, summed in light order from zero as
    # BLAS does (an unused term added as 0.0 changes nothing), one array per entry so the
    # loops over the block's pixels run in SIMD lanes
    m_b = np.empty((6, blk))
    rhs_b = np.empty((3, blk), dtype=np.float32)
    cnt = np.empty(blk, dtype=np.int64)
    # per block, pixel-major: a pixel's values contiguous for its passes
    g_b = np.empty((blk, n_img), dtype=np.float32)
    used_b = np.empty((blk, n_img), dtype=np.bool_)
    r = np.empty(n_img, dtype=np.float32)
    ra = np.empty(n_img, dtype=np.float32)
    cand = np.empty(n_img, dtype=np.float32)
    bits = np.empty(1, dtype=np.float32)
    m = np.empty(6)
    rhs = np.empty(3)
    b = np.empty(3)
    mt = np.empty(6)
    rhst = np.empty(3)
    bt = np.empty(3)
    for p0 in range(0, p_total, blk):
        nb = min(blk, p_total - p0)
        ins = inside[p0 : p0 + nb]
        m0, m1, m2, m3, m4, m5 = m_b[0], m_b[1], m_b[2], m_b[3], m_b[4], m_b[5]
        a0, a1, a2 = rhs_b[0], rhs_b[1], rhs_b[2]
        m_b[:] = 0.0
        rhs_b[:] = 0.0
        cnt[:] = 0
        for k in range(n_img):
            row = g[k, p0 : p0 + nb]
            c0, c1, c2, c3, c4, c5 = ll6[k, 0], ll6[k, 1], ll6[k, 2], ll6[k, 3], ll6[k, 4], ll6[k, 5]
            x, y, z = lx[k], ly[k], lz[k]
            for j in range(nb):
                v = row[j]
                u = ins[j] and v > dark and v < sat  # NaN: False
                cnt[j] += u
                w = 1.0 if u else 0.0
                m0[j] += c0 * w
                m1[j] += c1 * w
                m2[j] += c2 * w
                m3[j] += c3 * w
                m4[j] += c4 * w
                m5[j] += c5 * w
                gw = v if u else np.float32(0.0)
                a0[j] = _fma32(x, gw, a0[j])
                a1[j] = _fma32(y, gw, a1[j])
                a2[j] = _fma32(z, gw, a2[j])
            for j in range(nb):
                v = row[j]
                g_b[j, k] = v
                used_b[j, k] = ins[j] and v > dark and v < sat
        for q in range(nb):
            p = p0 + q
            n = cnt[q]
            for c in range(6):
                m[c] = m_b[c, q]
            for c in range(3):
                rhs[c] = rhs_b[c, q]
            gv, used = g_b[q], used_b[q]
            ok = _solve(m, rhs, n, cond2, b)
            if ok:
                n, ok = _pixel_passes(
                    gv, used, m, rhs, b, n, lx, ly, lz, ll6, lights, rules_f32, max_passes,
                    shadow_min_kept, cond2, r, ra, cand, bits, mt, rhst, bt,
                )
            # outputs: unit normal with z >= 0, albedo, RMS residual over the used observations
            b[2] = max(b[2], 0.0)  # a normal facing away from the camera is unseen
            norm = math.sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2])
            if not (ok and ins[q] and norm > eps_b):
                normals[p, 0], normals[p, 1], normals[p, 2] = 0.0, 0.0, 1.0
                albedo[p, :] = 0.0
                rms[p] = 0.0
                count_out[p] = 0
                ok_out[p] = False
                continue
            n0, n1, n2 = b[0] / norm, b[1] / norm, b[2] / norm
            normals[p, 0], normals[p, 1], normals[p, 2] = n0, n1, n2
            den = (
                m[0] * n0 * n0
                + m[3] * n1 * n1
                + m[5] * n2 * n2
                + 2.0 * (m[1] * n0 * n1 + m[2] * n0 * n2 + m[4] * n1 * n2)
            )
            if not den > 0:
                den = 1.0
            if grey:
                albedo[p, 0] = (n0 * rhs[0] + n1 * rhs[1] + n2 * rhs[2]) / den
            else:
                for c in range(channels):
                    s0 = s1 = s2 = np.float32(0.0)
                    for k in range(n_img):
                        v = colour[k, p, c] if used[k] else np.float32(0.0)
                        s0 = _fma32(lx[k], v, s0)
                        s1 = _fma32(ly[k], v, s1)
                        s2 = _fma32(lz[k], v, s2)
                    albedo[p, c] = (n0 * s0 + n1 * s1 + n2 * s2) / den
            bt[0], bt[1], bt[2] = n0 * norm, n1 * norm, n2 * norm
            _residuals(gv, lx, ly, lz, bt, r)
            ss = np.float32(0.0)
            for k in range(n_img):
                if used[k]:
                    ss += r[k] * r[k]
            rms[p] = math.sqrt(np.float64(ss) / n)
            count_out[p] = n
            ok_out[p] = True
