"""Order the stops of an arm schedule to minimise the total move time.

This is an open travelling-salesman path from the arm's start pose through every stop, with
the move-time model of :mod:`rti_rig.core.arm_motion` as the distance. Exact Held-Karp dynamic
programming up to :data:`EXACT_MAX` stops (2^12 * 12 states, vectorised with numpy: a few ms);
beyond that nearest-neighbour construction from several seeds, improved by 2-opt and Or-opt
(segments of 1-3 stops moved, possibly reversed) until no move helps, then iterated local
search (double-bridge kicks, kept when they shorten the path; deterministic seed). Above
:data:`FULL_SEARCH_MAX` stops 2-opt and Or-opt try only the moves that join a stop to one of
its :data:`NEIGHBOURS` nearest (neighbour lists), so a pass costs O(N * K) rather than
O(N^2) per move found. The benchmark (``python -m benchmarks.arm_order``) measures the
heuristic against the exact optimum at N = 14 and 16: median 0 %, worst 1.97 % above;
``python -m benchmarks.arm_order scaling`` the neighbour lists against every move tried.

The order does not change *what* is imaged, only when: the session still writes its ``.lp``
from what ran, in the order it ran.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.arm_motion import move_time_matrix, sequence_time_s

#: Largest stop count solved exactly.
EXACT_MAX = 12

#: Largest stop count whose 2-opt and Or-opt try every reversal and insertion point. Beyond it
#: they try only moves that make an edge to one of a stop's :data:`NEIGHBOURS` nearest stops
#: (neighbour lists, built once). Why: the exhaustive passes cost O(N^2) per move found, and the
#: whole search grew as N^2.4 (50 s at 1000 stops); below this size it is cheap (well under a
#: second) and the orders stay exactly the ones it gave.
FULL_SEARCH_MAX = 200

#: Neighbour-list length for the passes above :data:`FULL_SEARCH_MAX`. Bentley (1992, "Fast
#: algorithms for geometric traveling salesman problems", ORSA J. Computing 4(4)) and Johnson
#: & McGeoch (1997, "The traveling salesman problem: a case study in local optimization") keep
#: 2-opt and Or-opt to each city's 8-20 nearest neighbours at a fraction of a percent in tour
#: length; ``python -m benchmarks.arm_order`` measures it against the exhaustive passes here.
NEIGHBOURS = 12

#: Rows (segment starts) first evaluated at once by the neighbour-list passes: the first
#: improving move is usually near where the last was, so evaluating every remaining row each
#: time (as the exhaustive passes do) would make each move cost O(N).
_CHUNK = 32

#: ``progress(done, total)``: the heuristic's steps (each seed's descent, then each kick) as
#: they finish. Why: at 1000 stops the search takes seconds (it took a minute before the
#: neighbour lists), and ``plan`` had shown nothing in that time.
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
    """Greedy path from stop ``first``: always the nearest stop not yet visited (the lowest
    index among equal times). One numpy argmin per step: the Python ``min`` over a set it
    replaced took about a second per seed at 1000 stops."""
    n = cost.shape[0] - 1
    visited = np.zeros(n, dtype=bool)
    order = [first]
    visited[first] = True
    for _ in range(n - 1):
        row = np.where(visited, np.inf, cost[order[-1] + 1, 1:])
        nxt = int(np.argmin(row))
        order.append(nxt)
        visited[nxt] = True
    return order


def neighbour_lists(cost: NDArray[np.float64], k: int = NEIGHBOURS) -> NDArray[np.intp]:
    """Each matrix node's ``k`` nearest stops (matrix nodes >= 1, itself excluded), by the
    time both ways, nearest first; row 0 is the start's. Built once per search."""
    both = cost + cost.T
    both[:, 0] = np.inf
    np.fill_diagonal(both, np.inf)
    k = max(1, min(k, cost.shape[0] - 2))
    near = np.argpartition(both, k - 1, axis=1)[:, :k]
    keys = np.take_along_axis(both, near, axis=1)
    return np.take_along_axis(near, np.argsort(keys, axis=1, kind="stable"), axis=1)


def _positions(arr: NDArray[np.intp]) -> NDArray[np.intp]:
    """``pos[node]`` = the node's index in the path ``arr``."""
    pos = np.empty(len(arr), dtype=np.intp)
    pos[arr] = np.arange(len(arr))
    return pos


def _chunks(start: int, stop: int, near: bool) -> Iterator[tuple[int, int]]:
    """Row ranges to evaluate: all at once for the exhaustive passes; for the neighbour-list
    ones :data:`_CHUNK` rows first, each next range twice as long (the caller stops at the
    first range that has a move). Why doubling: a move is usually found in the first rows, and
    a pass that finds none scans all in a few numpy calls rather than N / 64 of them."""
    if not near:
        yield start, stop
        return
    size = _CHUNK
    while start < stop:
        yield start, min(start + size, stop)
        start, size = start + size, 2 * size


def _two_opt(
    nodes: list[int], cost: NDArray[np.float64], near: NDArray[np.intp] | None = None
) -> tuple[list[int], bool]:
    """One pass of 2-opt on an open path of matrix nodes (``nodes[0]`` is the fixed start).

    Deltas are exact for asymmetric costs (the reversed segment's inner edges are summed both
    ways with prefix sums). The segment starts are examined in path order: at the first that a
    reversal shortens, its best reversal is made and the same start examined again; the deltas
    of every remaining start and end are evaluated at once (:func:`_first_reversal`), with the
    same arithmetic as one start at a time. With neighbour lists ``near``, only the reversals
    that join a stop to one of its neighbours (or reverse the tail) are tried."""
    improved = False
    i = 1
    while True:
        move = _first_reversal(np.asarray(nodes), cost, i, near)
        if move is None:
            return nodes, improved
        i, k = move
        nodes = nodes[:i] + nodes[i : k + 1][::-1] + nodes[k + 1 :]
        improved = True


def _first_reversal(
    arr: NDArray[np.intp],
    cost: NDArray[np.float64],
    start: int,
    near: NDArray[np.intp] | None = None,
) -> tuple[int, int] | None:
    """The first segment start ``i`` (from path position ``start`` on) whose best reversal of
    ``arr[i..k]`` shortens the path, as (i, k), or None.

    Row ``r`` is the start ``i = start + r`` (after ``a = arr[i - 1]``, first stop ``b``);
    column ``k`` the segment's last stop ``c = arr[k]`` (``k > i``), followed by ``d``. Every
    ``k`` is a column, or with neighbour lists only those making ``a -> c`` or ``b -> d`` an
    edge to a neighbour, and the path's end."""
    m = len(arr)
    fwd = np.concatenate([[0.0], np.cumsum(cost[arr[:-1], arr[1:]])])
    bwd = np.concatenate([[0.0], np.cumsum(cost[arr[1:], arr[:-1]])])
    flat, width = np.ravel(cost), cost.shape[1]  # (rows × ends) lookups by flat index
    pos = _positions(arr) if near is not None else None
    for lo, hi in _chunks(start, m - 1, near is not None):
        ii = np.arange(lo, hi)
        a, b = arr[ii - 1], arr[ii]
        if near is None or pos is None:
            ks = np.broadcast_to(np.arange(m), (len(ii), m))
        else:
            ks = np.concatenate(
                [pos[near[a]], pos[near[b]] - 1, np.full((len(ii), 1), m - 1)], axis=1
            )
        c = arr[ks]
        delta = (
            flat[a[:, None] * width + c]
            - cost[a, b][:, None]
            + (bwd[ks] - bwd[ii][:, None])
            - (fwd[ks] - fwd[ii][:, None])
        )
        has_d = ks + 1 < m
        d = arr[np.minimum(ks + 1, m - 1)]
        delta = delta + np.where(has_d, flat[b[:, None] * width + d] - flat[c * width + d], 0.0)
        delta[ks <= ii[:, None]] = np.inf  # a segment ends after it starts
        rows = np.arange(len(ii))
        best = np.argmin(delta, axis=1)
        found = np.flatnonzero(delta[rows, best] < -1e-12)
        if len(found):
            r = int(found[0])
            return int(ii[r]), int(ks[r, best[r]])
    return None


def _or_opt(
    nodes: list[int], cost: NDArray[np.float64], near: NDArray[np.intp] | None = None
) -> tuple[list[int], bool]:
    """One pass of Or-opt: move a segment of 1-3 stops elsewhere, forwards or reversed.

    Exact deltas (edges removed and added, plus the inner edges' change when reversed). The
    segments are examined in path order and the first that can move is moved (then the same
    place is examined again); the deltas of every remaining segment and insertion point are
    evaluated at once, with the same arithmetic as one at a time. With neighbour lists
    ``near``, only insertions next to a neighbour of the segment's ends (or at either end of
    the path) are tried."""
    improved = False
    m = len(nodes)
    for seg in (1, 2, 3):
        i = 1
        while i + seg <= m:
            move = _first_segment_move(np.asarray(nodes), cost, seg, i, near)
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
    arr: NDArray[np.intp],
    cost: NDArray[np.float64],
    seg: int,
    start: int,
    near: NDArray[np.intp] | None = None,
) -> tuple[int, int, bool] | None:
    """The first segment (from path position ``start`` on) of ``seg`` stops that an Or-opt
    move shortens, as (position, insertion index into the path without it, reversed), or None.

    Row ``r`` is the segment at position ``i = start + r``; column ``jj`` inserts it after the
    ``jj``-th stop of the path without it (``x``), before the next (``y``, none at the end).
    Every ``jj`` is a column, or with neighbour lists only those putting a neighbour of the
    segment's first or last stop just before or after it, and the path's two ends."""
    m = len(arr)
    n_rest = m - seg
    pos = _positions(arr) if near is not None else None
    flat, width = np.ravel(cost), cost.shape[1]
    for lo, hi in _chunks(start, m - seg + 1, near is not None):
        ii = np.arange(lo, hi)
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
        if near is None or pos is None:
            jj = np.broadcast_to(np.arange(n_rest), (len(ii), n_rest))
            inside = np.zeros(jj.shape, dtype=bool)
        else:
            at = pos[np.concatenate([near[first], near[last]], axis=1)]
            inside = np.concatenate([(at >= ii[:, None]) & (at < (ii + seg)[:, None])] * 2, axis=1)
            rest_at = np.where(at >= ii[:, None] + seg, at - seg, at)
            ends = np.broadcast_to(np.array([0, n_rest - 1]), (len(ii), 2))
            jj = np.concatenate([rest_at, rest_at - 1, ends], axis=1)
            inside = np.concatenate([inside, np.zeros(ends.shape, dtype=bool)], axis=1)
            jj = np.maximum(jj, 0)
        after = jj >= ii[:, None]
        x = np.where(after, arr[np.minimum(jj + seg, m - 1)], arr[jj])
        yj = jj + 1
        has_y = yj < n_rest
        y = np.where(
            yj >= ii[:, None], arr[np.minimum(yj + seg, m - 1)], arr[np.minimum(yj, m - 1)]
        )
        y_safe = np.where(has_y, y, 0)
        # the (rows × insertion points) lookups as flat indices into the matrix (the same
        # entries; 2-D fancy indexing with broadcast index arrays was half of this time)
        xw = x * width
        opened = np.where(has_y, flat[xw + y_safe], 0.0)
        rows = np.arange(len(ii))
        best_delta = np.full(len(ii), -1e-12)
        best_pos = np.full(len(ii), -1)
        best_rev = np.zeros(len(ii), dtype=bool)
        for rev, a, b, inner in ((False, first, last, inner_f), (True, last, first, inner_b)):
            added = flat[xw + a[:, None]] + np.where(has_y, flat[b[:, None] * width + y_safe], 0.0)
            delta = (bridged - removed)[:, None] + (added - opened) + (inner - inner_f)[:, None]
            # where the segment came from, and neighbours inside the segment itself
            delta[(jj == (ii - 1)[:, None]) | inside] = np.inf
            j = np.argmin(delta, axis=1)
            dj = delta[rows, j]
            better = dj < best_delta
            best_delta = np.where(better, dj, best_delta)
            best_pos = np.where(better, jj[rows, j] + 1, best_pos)
            best_rev = np.where(better, rev, best_rev)
        found = np.flatnonzero(best_pos >= 0)
        if len(found):
            r = int(found[0])
            return int(ii[r]), int(best_pos[r]), bool(best_rev[r])
    return None


def _local_search(
    nodes: list[int],
    cost: NDArray[np.float64],
    max_rounds: int = 100,
    near: NDArray[np.intp] | None = None,
) -> list[int]:
    for _ in range(max_rounds):
        nodes, a = _two_opt(nodes, cost, near)
        nodes, b = _or_opt(nodes, cost, near)
        if not (a or b):
            break
    return nodes


def improve(
    order: list[int], cost: NDArray[np.float64], near: NDArray[np.intp] | None = None
) -> list[int]:
    """2-opt and Or-opt until neither helps; stops as 0-based indices. ``near``: neighbour
    lists (:func:`neighbour_lists`) to try only moves to neighbours; None tries every move."""
    nodes = _local_search([0, *[i + 1 for i in order]], cost, near=near)
    return [x - 1 for x in nodes[1:]]


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
    neighbours: int | None = None,
) -> list[int]:
    """Nearest neighbour from the ``seeds`` stops nearest the start, 2-opt + Or-opt, then
    iterated local search (double-bridge kicks, keep if better). Deterministic for a seed;
    ``progress`` is told each step done (it does not change the order).

    ``neighbours``: how many of each stop's nearest stops the passes try moves to; 0 tries
    every move; None (the default) is 0 up to :data:`FULL_SEARCH_MAX` stops and
    :data:`NEIGHBOURS` beyond."""
    n = cost.shape[0] - 1
    if n == 0:
        return []
    if neighbours is None:
        neighbours = 0 if n <= FULL_SEARCH_MAX else NEIGHBOURS
    near = neighbour_lists(cost, neighbours) if neighbours > 0 and n >= 2 else None
    firsts = list(np.argsort(cost[0, 1:])[: max(1, min(seeds, n))])
    kicks = (max(20, 2000 // n) if kicks is None else kicks) if n >= 8 else 0
    total = len(firsts) + kicks
    best, best_t = None, np.inf
    for done, f in enumerate(firsts, 1):
        cand = improve(_nearest_neighbour(cost, int(f)), cost, near)
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
        cand = _local_search(_double_bridge(nodes, rng), cost, near=near)
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
