"""The compiled per-pixel loop of robust photometric stereo (numba).

Imported only by :func:`rti_rig.reconstruct.robust_ps.fit_robust_band`, when a robust fit runs:
numba and llvmlite cost tens of MB of memory and a fraction of a second to import, which a
least-squares fit (whose memory is at relight's limit) must not pay.

Pixels are taken in blocks of :data:`BLOCK_PIXELS`: the block's normal equations are summed
across its pixels in SIMD lanes, straight from the band's light-major rows; then each pixel
runs its passes alone (rules 3 and 4 of :mod:`rti_rig.reconstruct.photometric_stereo`) on its
row of a pixel-major copy of the block's values, and its outputs are computed at once. Every
arithmetic step is the one the former numpy implementation (chunked, BLAS products) performed,
in the same order, so the fits were bit-identical to it when it was replaced (compared old
against new on the benchmark scene and 19 test scenes; no test keeps the old code, the tests
compare with a slow per-pixel reference within tolerances); the rewrite of 2026-11-24 (below)
was compared with the kernel before it, call by call, outputs equal bit for bit: the
benchmark scene, every call made by tests/reconstruct and by the adaptive and fit CLI tests
(1231), and 62 random bands with NaN, infinite, saturated and dark values, masks, colour,
3 to 130 lights and rule settings that reach the rare branches:

* float32 products accumulate with fused multiply-adds, one term after another in light order,
  as OpenBLAS's sgemm does (checked bit for bit): the residuals ``g - L b`` (K = 3), the
  initial ``sum I l`` (K = N), the colour projections, the RMS residual's prediction.
* float64 sums (``sum l l^T``, the downdates by the dropped terms) run in light order from zero.
* The 3 × 3 solve and its conditioning test are those of
  :func:`rti_rig.reconstruct.normal_equations.solve_normal_equations`, term for term (numba
  does not contract a product and a sum into a fused one without ``fastmath``). Only the
  trigonometric eigenvalues (needed where the cheap bound cannot decide) may differ from
  numpy's in the last bit, which matters only for a ratio within rounding of ``cond_limit``.

No median is computed. Each used |residual| is mapped to the threshold it would set as the
median, ``fl32(k * fl32(1.4826 * |r|))`` (monotone, so the lower median of these is the
threshold of the lower median); the threshold is the floor when more than half of them are at
most the floor, and otherwise a residual ``x`` above the floor exceeds it iff more than half
of them are below ``x`` (:func:`_exceeds`): one count per residual above the floor. A sort or
a selection of ~48 values costs more in mispredicted branches.

What the per-pixel path is made of (the rewrite of 2026-11-24): the passes hold the pixel's
normal equations, fit and downdates in scalars and index the pixel's row of the block copy in
place (``g_b[q, k]``): no array view is made per pixel or per pass, and the only helpers there
that take arrays are the small :func:`_scales` and :func:`_exceeds` (the kernel before called
an inlined pass helper taking 19 arrays per pixel: measured, ~60 ns per pixel with no pass
run at all). A drop clears its own entry of the light-major mask the outputs read
(``used_l``, set in the block set-up) instead of each pixel's final mask being transposed
into it. The counts, the largest single cost of the passes (~17 per pixel on the benchmark
scene, a count of 48 values each), compare 8 float32 lanes at once: one vector compare, a
move-mask and a popcount (:func:`_lanes_intrinsic`), where numba's own loop widened each
comparison to an int64 lane; the rows are padded with NaN to whole registers. The candidates
above the floor are kept as bits of 64-light words and visited lowest bit first (the light
order the sums need).

Measured at 512² × 48 lights (the fit_throughput scene: ~4.6 highlight passes, ~9 drops and
~17 counts per pixel), the kernel before and after timed alternately in one run on the
kernel's own arguments (median of 11, load average 4.6–5.0 on the 2 cores, CPU time):
203 → 118 ms, of which the block set-up, first solve and outputs (no pass run) 63 → 35 ms and
the passes ~140 → ~83 ms (~70 ns per highlight pass, the shadow pass included). Tried and
not faster: caching the largest value kept and the smallest dropped to skip counts (the
judgement is monotone), selects instead of the drop branch, two lights per sweep of the block
set-up, the residual loops over whole registers.

No ``parallel=True``: a band runs on one core (the benchmark's ratio is against a one-thread
product; callers that want cores fit bands in threads, which ``nogil`` allows).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core.errors import NumbaWarning
from numba.extending import intrinsic

#: Margin of the eigenvalue-free conditioning test (as in ``normal_equations``).
_BOUND_MARGIN = 0.99
#: Pixels per block: the block's work arrays (~30 KB at 48 lights) stay in the L1/L2 cache.
BLOCK_PIXELS = 128


def _jit(**options: Any) -> Callable[[Callable[..., Any]], Any]:
    """``njit(cache=True, nogil=True)``: compiled once, then loaded from numba's cache (next
    to this file, or in the user's cache folder when this folder is read-only). With no
    writable place at all numba refuses ``cache=True``; the kernel is then compiled in every
    process (seconds), said once by a :class:`NumbaWarning` — a warning about the process,
    which the fit's report leaves out (``fit_bands.fit_warnings``)."""

    def wrap(fn: Callable[..., Any]) -> Any:
        try:
            return njit(cache=True, nogil=True, **options)(fn)
        except RuntimeError as exc:  # "cannot cache function ...: no locator available"
            global _CACHE_WARNED
            if not _CACHE_WARNED:
                warnings.warn(
                    f"robust photometric stereo's kernel is compiled in every process: {exc}",
                    NumbaWarning,
                    stacklevel=2,
                )
                _CACHE_WARNED = True
            return njit(nogil=True, **options)(fn)

    return wrap


_CACHE_WARNED = False


@intrinsic
def _fma32(typingctx, a, b, c):  # type: ignore[no-untyped-def]
    """``fl32(a * b + c)`` rounded once (LLVM's fma: one instruction, vectorisable)."""
    sig = types.float32(types.float32, types.float32, types.float32)

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        return builder.fma(*args)

    return sig, codegen


@intrinsic
def _cttz(typingctx, x):  # type: ignore[no-untyped-def]
    """The index of the lowest set bit of ``x`` (uint64; 64 for zero): one instruction."""
    sig = types.int64(types.uint64)

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        return builder.cttz(args[0], ir.Constant(ir.IntType(1), 0))

    return sig, codegen


#: SIMD width of the comparisons below (8 float32 lanes: one AVX register).
LANES = 8


def _lanes_intrinsic(op: str, count: bool) -> Any:
    """An intrinsic ``f(arr, j, x)``: the comparisons ``arr[j + i] <op> x`` (float32, ordered:
    NaN compares False) of the 8 lanes ``i`` as a bit mask (bit ``i``), or their count: one
    vector compare, a move-mask and a popcount, where numba's loop widens each comparison to
    an int64 lane. ``arr`` must hold ``j + 8`` values (the kernel pads with NaN)."""

    @intrinsic
    def lanes(typingctx, arr, j, x):  # type: ignore[no-untyped-def]
        if not (
            isinstance(arr, types.Array)
            and arr.dtype == types.float32
            and arr.ndim == 1
            and arr.layout == "C"
        ):
            return None  # a typing error: the load below reads 8 contiguous float32
        sig = types.int64(arr, j, types.float32)

        def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
            ary = context.make_array(signature.args[0])(context, builder, args[0])
            vty = ir.VectorType(ir.FloatType(), LANES)
            ptr = builder.bitcast(builder.gep(ary.data, [args[1]]), vty.as_pointer())
            vec = builder.load(ptr, align=4)
            xs = builder.insert_element(
                ir.Constant(vty, ir.Undefined), args[2], ir.Constant(ir.IntType(32), 0)
            )
            zeros = ir.Constant(ir.VectorType(ir.IntType(32), LANES), [0] * LANES)
            xs = builder.shuffle_vector(xs, ir.Constant(vty, ir.Undefined), zeros)
            bits = builder.bitcast(builder.fcmp_ordered(op, vec, xs), ir.IntType(LANES))
            if count:
                bits = builder.ctpop(bits)
            return builder.zext(bits, ir.IntType(64))

        return sig, codegen

    return lanes


_bits_gt = _lanes_intrinsic(">", count=False)
_count_lt = _lanes_intrinsic("<", count=True)
_count_le = _lanes_intrinsic("<=", count=True)


@_jit()
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


@_jit(inline="always")
def _solve(a, bb, c, d, e, f, r0, r1, r2, count, cond2):  # type: ignore[no-untyped-def]
    """Solve ``m b = rhs`` (``m``: the six entries of the symmetric 3 × 3 matrix, ``rhs``
    ``r0, r1, r2``) as ``solve_normal_equations`` does (zero where unsolvable; ``cond2``:
    ``cond_limit**2``); returns whether the pixel is solvable and ``b``. Scalars in, scalars
    out: no array (whose reference count numba would update on every call) in the passes."""
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
    b0 = (co_a * r0 + co_b * r1 + co_c * r2) * inv_det
    b1 = (co_b * r0 + co_d * r1 + co_e * r2) * inv_det
    b2 = (co_c * r0 + co_e * r1 + co_f * r2) * inv_det
    return ok, b0, b1, b2


@_jit(inline="always")
def _scales(r, scale, mad, sc):  # type: ignore[no-untyped-def]
    """``sc = fl32(scale * fl32(mad * |r|))`` (``mad``: 1.4826, the MAD's scale to a sigma):
    each |residual| as the threshold it would set as the median (NaN where unused). Monotone
    in |r|, so the lower median of ``sc`` is the threshold of the lower median of |r|, before
    the floor."""
    for k in range(r.shape[0]):
        sc[k] = scale * (mad * abs(r[k]))


@_jit(inline="always")
def _count_below(sc, x):  # type: ignore[no-untyped-def]
    """How many values of ``sc`` are below ``x`` (NaN: not counted), 8 lanes at a time."""
    n8 = sc.shape[0] // LANES * LANES
    below = 0
    for j in range(0, n8, LANES):
        below += _count_lt(sc, j, x)
    for k in range(n8, sc.shape[0]):
        below += sc[k] < x
    return below


@_jit(inline="always")
def _exceeds(x, sc, n, floor):  # type: ignore[no-untyped-def]
    """Whether ``x > max(median threshold, floor)`` (the lower median, index ``(n - 1) // 2``
    sorted, of the ``n`` used values of ``sc``, see ``_scales``) without the median: ``x``
    exceeds it iff more than ``(n - 1) // 2`` used values are below ``x``."""
    if not x > floor:
        return False
    return _count_below(sc, x) > (n - 1) // 2


@_jit()
def fit_pixels(  # type: ignore[no-untyped-def]
    g,
    inside,
    colour,
    lights,
    dark,
    sat,
    rules_f32,
    max_passes,
    shadow_min_kept,
    cond2,
    eps_b,
    normals,
    albedo,
    rms,
    count_out,
    ok_out,
):
    """The robust fit of every pixel of ``g`` (N, P) float32 (C order; NaN, infinite and
    saturated values are not used), ``inside`` (P,) the mask, ``colour`` (N, P, C) float32
    (unusable values zeroed) or an empty array for grey albedo from the normal equations,
    ``lights`` (N, 3) float64; ``dark``, ``sat`` float32; ``rules_f32``: highlight_k, shadow_k
    (0: rule 4 off), floor and the MAD's scale, float32 (passed, not constants of this
    module's: numba's cache is keyed by this file alone, so a constant imported from another
    would be frozen in a stale cache). Writes ``normals`` (P, 3), ``albedo`` (P, C), ``rms``
    (P,), ``count_out`` (P,) and ``ok_out`` (P,).
    """
    n_img, p_total = g.shape
    grey = colour.shape[0] == 0
    channels = albedo.shape[1]
    highlight_k, shadow_k, floor, mad = rules_f32[0], rules_f32[1], rules_f32[2], rules_f32[3]
    nan = np.float32(np.nan)
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
    # a pixel's residuals and their thresholds (see _exceeds), padded with NaN to whole SIMD
    # registers for the compare intrinsics; the candidates above the floor as bits
    n_pad = (n_img + LANES - 1) // LANES * LANES
    r = np.full(n_pad, np.nan, dtype=np.float32)
    sc = np.full(n_pad, np.nan, dtype=np.float32)
    n_words = (n_img + 63) // 64
    cand = np.empty(n_words, dtype=np.uint64)
    # per block, light-major again for the outputs: unit normals and albedo denominators,
    # fitted b as float32, the used observations (a drop clears its own), sums
    n_b = np.empty((4, blk))
    b32 = np.empty((3, blk), dtype=np.float32)
    used_l = np.empty((n_img, blk), dtype=np.bool_)
    acc_b = np.empty((3, blk), dtype=np.float32)
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
            uk = used_l[k]
            c0, c1, c2 = ll6[k, 0], ll6[k, 1], ll6[k, 2]
            c3, c4, c5 = ll6[k, 3], ll6[k, 4], ll6[k, 5]
            x, y, z = lx[k], ly[k], lz[k]
            for j in range(nb):
                v = row[j]
                u = ins[j] and v > dark and v < sat  # NaN: False
                uk[j] = u
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
            for j in range(nb):  # pixel-major, NaN where unused
                v = row[j]
                g_b[j, k] = v if ins[j] and v > dark and v < sat else nan
        # each pixel alone: its passes on scalars and on g_b[q] (a dropped observation becomes
        # NaN there and is cleared in used_l), indexed in place: no array view per pixel
        for q in range(nb):
            p = p0 + q
            n = cnt[q]
            e0, e1, e2 = m_b[0, q], m_b[1, q], m_b[2, q]
            e3, e4, e5 = m_b[3, q], m_b[4, q], m_b[5, q]
            s0, s1, s2 = np.float64(rhs_b[0, q]), np.float64(rhs_b[1, q]), np.float64(rhs_b[2, q])
            ok, b0, b1, b2 = _solve(e0, e1, e2, e3, e4, e5, s0, s1, s2, n, cond2)
            if ok:
                # rule 3: highlights, every used residual above the threshold per pass, then
                # a refit
                for _ in range(max_passes):
                    f0, f1, f2 = np.float32(b0), np.float32(b1), np.float32(b2)
                    for k in range(n_img):  # r = g - fl32(L b) as BLAS, NaN where unused
                        r[k] = g_b[q, k] - _fma32(lz[k], f2, _fma32(ly[k], f1, lx[k] * f0))
                    cand[:] = 0
                    for j in range(0, n_pad, LANES):
                        cand[j >> 6] |= np.uint64(_bits_gt(r, j, floor)) << np.uint64(j & 63)
                    any_over = False
                    for w in range(n_words):
                        any_over = any_over or cand[w] != 0
                    if not any_over:
                        break
                    _scales(r, highlight_k, mad, sc)
                    small = 0
                    for j in range(0, n_pad, LANES):
                        small += _count_le(sc, j, floor)
                    # the threshold is the floor when the median's is at most the floor; else
                    # each residual above the floor is judged by a count (no median computed)
                    half = (n - 1) // 2
                    at_floor = small > half
                    # the dropped terms summed in light order from zero, then subtracted (as
                    # bincount did)
                    t0 = t1 = t2 = t3 = t4 = t5 = 0.0
                    u0 = u1 = u2 = 0.0
                    dropped = 0
                    for w in range(n_words):
                        bits = cand[w]
                        while bits != 0:  # the candidates above the floor, in light order
                            k = w * 64 + _cttz(bits)
                            bits &= bits - np.uint64(1)
                            x = r[k]
                            if not (at_floor or _exceeds(x, sc, n, floor)):
                                continue
                            t0 += ll6[k, 0]
                            t1 += ll6[k, 1]
                            t2 += ll6[k, 2]
                            t3 += ll6[k, 3]
                            t4 += ll6[k, 4]
                            t5 += ll6[k, 5]
                            v64 = np.float64(g_b[q, k])
                            u0 += v64 * lights[k, 0]
                            u1 += v64 * lights[k, 1]
                            u2 += v64 * lights[k, 2]
                            g_b[q, k] = nan
                            used_l[k, q] = False
                            dropped += 1
                    if dropped == 0:
                        break
                    e0 -= t0
                    e1 -= t1
                    e2 -= t2
                    e3 -= t3
                    e4 -= t4
                    e5 -= t5
                    s0 -= u0
                    s1 -= u1
                    s2 -= u2
                    n -= dropped
                    ok, b0, b1, b2 = _solve(e0, e1, e2, e3, e4, e5, s0, s1, s2, n, cond2)
                    if not ok:
                        break
            if ok and shadow_k > 0:
                # rule 4: partial shadows, the darkest observation per pass
                for _ in range(max_passes):
                    if n <= shadow_min_kept:
                        break
                    f0, f1, f2 = np.float32(b0), np.float32(b1), np.float32(b2)
                    low = np.float32(np.inf)
                    for k in range(n_img):  # a select, not a branch (NaN: not taken)
                        rk = g_b[q, k] - _fma32(lz[k], f2, _fma32(ly[k], f1, lx[k] * f0))
                        r[k] = rk
                        low = rk if rk < low else low
                    x = -low
                    if not x > floor:
                        break
                    _scales(r, shadow_k, mad, sc)
                    if not _exceeds(x, sc, n, floor):
                        break
                    worst = 0
                    while r[worst] != low:  # the first at the minimum, as argmin picks it
                        worst += 1
                    v64 = np.float64(g_b[q, worst])
                    d0 = e0 - (0.0 + ll6[worst, 0])
                    d1 = e1 - (0.0 + ll6[worst, 1])
                    d2 = e2 - (0.0 + ll6[worst, 2])
                    d3 = e3 - (0.0 + ll6[worst, 3])
                    d4 = e4 - (0.0 + ll6[worst, 4])
                    d5 = e5 - (0.0 + ll6[worst, 5])
                    w0 = s0 - (0.0 + v64 * lights[worst, 0])
                    w1 = s1 - (0.0 + v64 * lights[worst, 1])
                    w2 = s2 - (0.0 + v64 * lights[worst, 2])
                    okt, c0, c1, c2 = _solve(d0, d1, d2, d3, d4, d5, w0, w1, w2, n - 1, cond2)
                    if not okt:
                        break  # a drop that leaves the pixel unsolvable is not made
                    g_b[q, worst] = nan
                    used_l[worst, q] = False
                    n -= 1
                    e0, e1, e2, e3, e4, e5 = d0, d1, d2, d3, d4, d5
                    s0, s1, s2 = w0, w1, w2
                    b0, b1, b2 = c0, c1, c2
            # outputs: unit normal with z >= 0, albedo, RMS residual over the used observations
            b2 = max(b2, 0.0)  # a normal facing away from the camera is unseen
            norm = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
            if not (ok and ins[q] and norm > eps_b):
                normals[p, 0], normals[p, 1], normals[p, 2] = 0.0, 0.0, 1.0
                for c in range(channels):
                    albedo[p, c] = 0.0
                rms[p] = 0.0
                count_out[p] = 0
                ok_out[p] = False
                b32[0, q] = b32[1, q] = b32[2, q] = 0.0
                continue
            n0, n1, n2 = b0 / norm, b1 / norm, b2 / norm
            normals[p, 0], normals[p, 1], normals[p, 2] = n0, n1, n2
            den = (
                e0 * n0 * n0
                + e3 * n1 * n1
                + e5 * n2 * n2
                + 2.0 * (e1 * n0 * n1 + e2 * n0 * n2 + e4 * n1 * n2)
            )
            if not den > 0:
                den = 1.0
            if grey:
                albedo[p, 0] = (n0 * s0 + n1 * s1 + n2 * s2) / den
            n_b[0, q], n_b[1, q], n_b[2, q], n_b[3, q] = n0, n1, n2, den
            # the fitted b (z-clamped) as float32, for the residual below
            b32[0, q], b32[1, q], b32[2, q] = n0 * norm, n1 * norm, n2 * norm
            count_out[p] = n
            ok_out[p] = True
        # across the block's pixels (SIMD lanes), each summed in light order: the RMS residual
        # over the used observations (float32, as numpy summed it) and the colour projections
        # (a pixel that is not ok keeps whatever its used_l says: its sums are not read)
        ok_b = ok_out[p0 : p0 + nb]
        ss = acc_b[0]
        ss[:] = 0.0
        bx, by, bz = b32[0], b32[1], b32[2]
        for k in range(n_img):
            row, uk = g[k, p0 : p0 + nb], used_l[k]
            x, y, z = lx[k], ly[k], lz[k]
            for j in range(nb):
                d = row[j] - _fma32(z, bz[j], _fma32(y, by[j], x * bx[j]))
                ss[j] += d * d if uk[j] else np.float32(0.0)
        for q in range(nb):
            if ok_b[q]:
                rms[p0 + q] = math.sqrt(np.float64(ss[q]) / count_out[p0 + q])
        if not grey:
            c0v, c1v, c2v = acc_b[0], acc_b[1], acc_b[2]
            for c in range(channels):
                acc_b[:] = 0.0
                for k in range(n_img):
                    uk = used_l[k]
                    x, y, z = lx[k], ly[k], lz[k]
                    for j in range(nb):
                        v = colour[k, p0 + j, c] if uk[j] else np.float32(0.0)
                        c0v[j] = _fma32(x, v, c0v[j])
                        c1v[j] = _fma32(y, v, c1v[j])
                        c2v[j] = _fma32(z, v, c2v[j])
                for q in range(nb):
                    if ok_b[q]:
                        n0, n1, n2, den = n_b[0, q], n_b[1, q], n_b[2, q], n_b[3, q]
                        albedo[p0 + q, c] = (n0 * c0v[q] + n1 * c1v[q] + n2 * c2v[q]) / den
