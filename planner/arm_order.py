"""Order the stops of an arm schedule to minimise the total move time.

This is an open travelling-salesman path from the arm's start pose through every stop, with
the move-time model of :mod:`rti_rig.core.arm_motion` as the distance. Exact Held-Karp dynamic
programming up to :data:`EXACT_MAX` stops (2^12 * 12 states, vectorised with numpy: a few ms);
beyond that nearest-neighbour construction from several seeds, improved by 2-opt and Or-opt
(segments of 1-3 stops moved, possibly reversed) until no move helps, then iterated local
search (double-bridge kicks, kept when they shorten the path; deterministic seed). The
benchmark (``python -m benchmarks.arm_order``) measures the heuristic against the exact
optimum at N = 14 and 16: median 0 %, worst 1.97 % above.

The order does not change *what* is imaged, only when: the session still writes its ``.lp``
from what ran, in the order it ran.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.arm_motion import move_time_matrix, sequence_time_s

#: Largest stop count solved exactly.
EXACT_MAX = 12

#: ``progress(done, total)``: the heuristic's steps (each seed's descent, then each kick) as
#: they finish. Why: at 1000 stops the search takes a minute or more, and ``plan`` had shown
#: nothing in that time.
Progress = Callable[[int, int], None]


def path_time_s(order: list[int] | NDArray, cost: NDArray[np.float64]) -> float:
    """Total time of visiting stops ``order`` (0-based) from node 0 of ``cost`` (the start)."""
    nodes = [0, *[int(i) + 1 for i in order]]
    idx = np.asarray(nodes)
    return float(cost[idx[:-1], idx[1:]].sum())


def held_karp(cost: NDArray[np.float64]) -> list[int]:
    """Exact shortest open path from node 0 through all other nodes; returns 0-based stops.

    ``dp[mask, j]`` is the best time from the start through the stops in ``mask`` ending at
    stop ``j``; layers of equal popcount are filled with one numpy operation per end stop."""
    n = cost.shape[0] - 1
    if n == 0:
        return []
    c = cost[1:, 1:]
    full = 1 << n
    dp = np.full((full, n), np.inf)
    parent = np.full((full, n), -1, dtype=np.int64)
    for j in range(n):
        dp[1 << j, j] = cost[0, j + 1]
    masks = np.arange(full)
    popcount = np.array([bin(m).count("1") for m in range(full)])
    for size in range(2, n + 1):
        layer = masks[popcount == size]
        for j in range(n):
            sel = layer[(layer >> j) & 1 == 1]
            prev = sel ^ (1 << j)
            totals = dp[prev] + c[:, j][None, :]
            best = np.argmin(totals, axis=1)
            dp[sel, j] = totals[np.arange(len(sel)), best]
            parent[sel, j] = best
    mask, j = full - 1, int(np.argmin(dp[full - 1]))
    order = []
    while j >= 0:
        order.append(j)
        mask, j = mask ^ (1 << j), int(parent[mask, j])
    return order[::-1]


def _nearest_neighbour(cost: NDArray[np.float64], first: int) -> list[int]:
    n = cost.shape[0] - 1
    left = set(range(n))
    order = [first]
    left.remove(first)
    while left:
        here = order[-1] + 1
        nxt = min(left, key=lambda k: cost[here, k + 1])
        order.append(nxt)
        left.remove(nxt)
    return order


def _two_opt(nodes: list[int], cost: NDArray[np.float64]) -> tuple[list[int], bool]:
    """One pass of 2-opt on an open path of matrix nodes (``nodes[0]`` is the fixed start).

    Deltas are exact for asymmetric costs (the reversed segment's inner edges are summed both
    ways with prefix sums). The segment starts are examined in path order: at the first that a
    reversal shortens, its best reversal is made and the same start examined again; the deltas
    of every remaining start and end are evaluated at once (:func:`_first_reversal`), with the
    same arithmetic as one start at a time."""
    improved = False
    i = 1
    while True:
        move = _first_reversal(np.asarray(nodes), cost, i)
        if move is None:
            return nodes, improved
        i, k = move
        nodes = nodes[:i] + nodes[i : k + 1][::-1] + nodes[k + 1 :]
        improved = True


def _first_reversal(
    arr: NDArray[np.intp], cost: NDArray[np.float64], start: int
) -> tuple[int, int] | None:
    """The first segment start ``i`` (from path position ``start`` on) whose best reversal of
    ``arr[i..k]`` shortens the path, as (i, k), or None.

    Row ``r`` is the start ``i = start + r`` (after ``a = arr[i - 1]``, first stop ``b``);
    column ``k`` the segment's last stop ``c = arr[k]`` (``k > i``), followed by ``d``."""
    m = len(arr)
    ii = np.arange(start, m - 1)
    if len(ii) == 0:
        return None
    fwd = np.concatenate([[0.0], np.cumsum(cost[arr[:-1], arr[1:]])])
    bwd = np.concatenate([[0.0], np.cumsum(cost[arr[1:], arr[:-1]])])
    a, b = arr[ii - 1], arr[ii]
    ks = np.arange(m)
    c = arr[ks]
    flat, width = np.ravel(cost), cost.shape[1]  # (rows × ends) lookups by flat index
    delta = (
        flat[a[:, None] * width + c[None, :]]
        - cost[a, b][:, None]
        + (bwd[ks][None, :] - bwd[ii][:, None])
        - (fwd[ks][None, :] - fwd[ii][:, None])
    )
    has_d = ks + 1 < m
    d = arr[np.minimum(ks + 1, m - 1)]
    delta = delta + np.where(
        has_d[None, :], flat[b[:, None] * width + d[None, :]] - cost[c, d][None, :], 0.0
    )
    delta[ks[None, :] <= ii[:, None]] = np.inf  # a segment ends after it starts
    best = np.argmin(delta, axis=1)
    found = np.flatnonzero(delta[np.arange(len(ii)), best] < -1e-12)
    if len(found) == 0:
        return None
    r = int(found[0])
    return int(ii[r]), int(best[r])


def _or_opt(nodes: list[int], cost: NDArray[np.float64]) -> tuple[list[int], bool]:
    """One pass of Or-opt: move a segment of 1-3 stops elsewhere, forwards or reversed.

    Exact deltas (edges removed and added, plus the inner edges' change when reversed). The
    segments are examined in path order and the first that can move is moved (then the same
    place is examined again); the deltas of every remaining segment and insertion point are
    evaluated at once, with the same arithmetic as one at a time."""
    improved = False
    m = len(nodes)
    for seg in (1, 2, 3):
        i = 1
        while i + seg <= m:
            move = _first_segment_move(np.asarray(nodes), cost, seg, i)
            if move is None:
                break
            i, pos, rev = move
            s = nodes[i : i + seg]
            rest_l = nodes[:i] + nodes[i + seg :]
            piece = s[::-1] if rev else s
            nodes = rest_l[:pos] + piece + rest_l[pos:]
            improved = True
    return nodes, improved


def _first_segment_move(
    arr: NDArray[np.intp], cost: NDArray[np.float64], seg: int, start: int
) -> tuple[int, int, bool] | None:
    """The first segment (from path position ``start`` on) of ``seg`` stops that an Or-opt
    move shortens, as (position, insertion index into the path without it, reversed), or None.

    Row ``r`` is the segment at position ``i = start + r``; column ``jj`` inserts it after the
    ``jj``-th stop of the path without it (``x``), before the next (``y``, none at the end)."""
    m = len(arr)
    ii = np.arange(start, m - seg + 1)
    if len(ii) == 0:
        return None
    first, last = arr[ii], arr[ii + seg - 1]
    p = arr[ii - 1]
    has_q = ii + seg < m
    q = arr[np.minimum(ii + seg, m - 1)]
    removed = cost[p, first] + np.where(has_q, cost[last, q], 0.0)
    bridged = np.where(has_q, cost[p, q], 0.0)
    inner_f = np.zeros(len(ii))
    inner_b = np.zeros(len(ii))
    for t in range(seg - 1):
        inner_f = inner_f + cost[arr[ii + t], arr[ii + t + 1]]
        inner_b = inner_b + cost[arr[ii + t + 1], arr[ii + t]]
    # the path without the segment: rest[jj] = arr[jj] before it, arr[jj + seg] after it
    n_rest = m - seg
    jj = np.arange(n_rest)[None, :]
    after = jj >= ii[:, None]
    x = np.where(after, arr[np.minimum(jj + seg, m - 1)], arr[jj])
    yj = jj + 1
    has_y = yj < n_rest
    y = np.where(yj >= ii[:, None], arr[np.minimum(yj + seg, m - 1)], arr[np.minimum(yj, m - 1)])
    y_safe = np.where(has_y, y, 0)
    # the (rows × insertion points) lookups as flat indices into the matrix (the same entries;
    # 2-D fancy indexing with broadcast index arrays was half of this function's time)
    flat, width = np.ravel(cost), cost.shape[1]
    xw = x * width
    opened = np.where(has_y, flat[xw + y_safe], 0.0)
    rows = np.arange(len(ii))
    best_delta = np.full(len(ii), -1e-12)
    best_pos = np.full(len(ii), -1)
    best_rev = np.zeros(len(ii), dtype=bool)
    for rev, a, b, inner in ((False, first, last, inner_f), (True, last, first, inner_b)):
        added = flat[xw + a[:, None]] + np.where(has_y, flat[b[:, None] * width + y_safe], 0.0)
        delta = (bridged - removed)[:, None] + (added - opened) + (inner - inner_f)[:, None]
        delta[rows, ii - 1] = np.inf  # that is where the segment came from
        j = np.argmin(delta, axis=1)
        dj = delta[rows, j]
        better = dj < best_delta
        best_delta = np.where(better, dj, best_delta)
        best_pos = np.where(better, j + 1, best_pos)
        best_rev = np.where(better, rev, best_rev)
    found = np.flatnonzero(best_pos >= 0)
    if len(found) == 0:
        return None
    r = int(found[0])
    return int(ii[r]), int(best_pos[r]), bool(best_rev[r])


def _local_search(nodes: list[int], cost: NDArray[np.float64], max_rounds: int = 100) -> list[int]:
    for _ in range(max_rounds):
        nodes, a = _two_opt(nodes, cost)
        nodes, b = _or_opt(nodes, cost)
        if not (a or b):
            break
    return nodes


def improve(order: list[int], cost: NDArray[np.float64]) -> list[int]:
    """2-opt and Or-opt until neither helps; stops as 0-based indices."""
    return [x - 1 for x in _local_search([0, *[i + 1 for i in order]], cost)[1:]]


def _double_bridge(nodes: list[int], rng: np.random.Generator) -> list[int]:
    """Classic ILS kick: cut the path (after the fixed start) in four and swap the middle two."""
    n = len(nodes) - 1
    a, b, c = sorted(int(v) for v in rng.choice(np.arange(1, n + 1), size=3, replace=False))
    return nodes[:a] + nodes[b:c] + nodes[a:b] + nodes[c:]


def heuristic_order(
    cost: NDArray[np.float64],
    seeds: int = 4,
    kicks: int | None = None,
    seed: int = 0,
    progress: Progress | None = None,
) -> list[int]:
    """Nearest neighbour from the ``seeds`` stops nearest the start, 2-opt + Or-opt, then
    iterated local search (double-bridge kicks, keep if better). Deterministic for a seed;
    ``progress`` is told each step done (it does not change the order)."""
    n = cost.shape[0] - 1
    if n == 0:
        return []
    firsts = list(np.argsort(cost[0, 1:])[: max(1, min(seeds, n))])
    kicks = (max(20, 2000 // n) if kicks is None else kicks) if n >= 8 else 0
    total = len(firsts) + kicks
    best, best_t = None, np.inf
    for done, f in enumerate(firsts, 1):
        cand = improve(_nearest_neighbour(cost, int(f)), cost)
        t = path_time_s(cand, cost)
        if t < best_t:
            best, best_t = cand, t
        if progress is not None:
            progress(done, total)
    assert best is not None
    if n < 8:
        return best
    rng = np.random.default_rng(seed)
    nodes = [0, *[i + 1 for i in best]]
    for k in range(kicks):
        cand = _local_search(_double_bridge(nodes, rng), cost)
        t = path_time_s([x - 1 for x in cand[1:]], cost)
        if t < best_t - 1e-12:
            nodes, best_t = cand, t
        if progress is not None:
            progress(len(firsts) + k + 1, total)
    return [x - 1 for x in nodes[1:]]


def order_from_matrix(cost: NDArray[np.float64], progress: Progress | None = None) -> list[int]:
    """Exact when at most :data:`EXACT_MAX` stops (a few ms: no progress), heuristic beyond."""
    n = cost.shape[0] - 1
    if n <= EXACT_MAX:
        return held_karp(cost)
    return heuristic_order(cost, progress=progress)


def order_for_arm(
    directions: ArrayLike, start: ArrayLike | None, settings: Any, progress: Progress | None = None
) -> list[int]:
    """Permutation of ``range(len(directions))`` minimising total move time from ``start``
    (the lamp's current direction; ``None`` = the park pose).

    When the azimuth joint spans more than a turn (multi-turn), the move time depends on the
    path, so two orders are computed (azimuth fixed near the start, and azimuth the short way
    round) and the one whose driver-faithful :func:`sequence_time_s` is lower is returned;
    ``progress`` then counts both searches' steps as one."""
    dirs = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    twice = settings.azimuth.max_deg - settings.azimuth.min_deg > 360.0 and len(dirs) >= 2

    def part(first: bool) -> Progress | None:
        if progress is None or not twice:
            return progress
        return lambda done, total: progress(done + (0 if first else total), 2 * total)

    order = order_from_matrix(move_time_matrix(dirs, settings, start), part(True))
    if not twice:
        return order
    other = order_from_matrix(move_time_matrix(dirs, settings, start, cyclic=True), part(False))
    t_fixed = sequence_time_s(dirs[order], settings, start)
    t_cyclic = sequence_time_s(dirs[other], settings, start)
    return other if t_cyclic < t_fixed else order
