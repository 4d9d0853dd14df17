"""Order the stops of an arm schedule to minimise the total move time.

This is an open travelling-salesman path from the arm's start pose through every stop, with
the move-time model of :mod:`planner.arm_motion` as the distance. Exact Held-Karp dynamic
programming up to :data:`EXACT_MAX` stops (2^12 * 12 states, vectorised with numpy: a few ms);
beyond that nearest-neighbour construction from several seeds, improved by 2-opt and Or-opt
(segments of 1-3 stops moved, possibly reversed) until no move helps.

The order does not change *what* is imaged, only when: the session still writes its ``.lp``
from what ran, in the order it ran.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planner.arm_motion import move_time_matrix

#: Largest stop count solved exactly.
EXACT_MAX = 12


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


def _two_opt(order: list[int], cost: NDArray[np.float64]) -> tuple[list[int], bool]:
    """One pass of 2-opt on the open path (node 0 fixed first; the end is free).

    Deltas are exact for asymmetric costs: the reversed segment's inner edges are summed both
    ways with prefix sums."""
    nodes = [0, *[i + 1 for i in order]]
    improved = False
    m = len(nodes)
    i = 1
    while i < m - 1:
        arr = np.array(nodes)
        fwd = np.concatenate([[0.0], np.cumsum(cost[arr[:-1], arr[1:]])])
        bwd = np.concatenate([[0.0], np.cumsum(cost[arr[1:], arr[:-1]])])
        changed = False
        for k in range(i + 1, m):
            a, b, c = nodes[i - 1], nodes[i], nodes[k]
            inner = (bwd[k] - bwd[i]) - (fwd[k] - fwd[i])
            delta = cost[a, c] - cost[a, b] + inner
            if k + 1 < m:
                d = nodes[k + 1]
                delta += cost[b, d] - cost[c, d]
            if delta < -1e-12:
                nodes = nodes[:i] + nodes[i:k + 1][::-1] + nodes[k + 1:]
                improved = changed = True
                break
        if not changed:
            i += 1
    return [x - 1 for x in nodes[1:]], improved


def _or_opt(order: list[int], cost: NDArray[np.float64]) -> tuple[list[int], bool]:
    """One pass of Or-opt: move a segment of 1-3 stops elsewhere, forwards or reversed.

    Exact deltas: edges removed and added around the segment, plus the change of its inner
    edges when it is reversed."""
    nodes = [0, *[i + 1 for i in order]]
    improved = False
    for seg in (1, 2, 3):
        i = 1
        while i + seg <= len(nodes):
            s = nodes[i:i + seg]
            p = nodes[i - 1]
            q = nodes[i + seg] if i + seg < len(nodes) else None
            removed = cost[p, s[0]] + (cost[s[-1], q] if q is not None else 0.0)
            bridged = cost[p, q] if q is not None else 0.0
            inner_f = sum(cost[s[t], s[t + 1]] for t in range(seg - 1))
            inner_b = sum(cost[s[t + 1], s[t]] for t in range(seg - 1))
            rest = nodes[:i] + nodes[i + seg:]
            best_delta, best_move = -1e-12, None
            for pos in range(1, len(rest) + 1):  # insert between rest[pos-1] and rest[pos]
                x = rest[pos - 1]
                y = rest[pos] if pos < len(rest) else None
                if x == p:
                    continue
                opened = cost[x, y] if y is not None else 0.0
                for rev, piece, inner in ((False, s, inner_f), (True, s[::-1], inner_b)):
                    added = cost[x, piece[0]] + (cost[piece[-1], y] if y is not None else 0.0)
                    delta = (bridged - removed) + (added - opened) + (inner - inner_f)
                    if delta < best_delta:
                        best_delta, best_move = delta, (pos, rev)
            if best_move is not None:
                pos, rev = best_move
                piece = s[::-1] if rev else s
                nodes = rest[:pos] + piece + rest[pos:]
                improved = True
            else:
                i += 1
    return [x - 1 for x in nodes[1:]], improved


def improve(order: list[int], cost: NDArray[np.float64], max_rounds: int = 50) -> list[int]:
    """2-opt and Or-opt until neither helps (or ``max_rounds``)."""
    for _ in range(max_rounds):
        order, a = _two_opt(order, cost)
        order, b = _or_opt(order, cost)
        if not (a or b):
            break
    return order


def heuristic_order(cost: NDArray[np.float64], seeds: int = 4) -> list[int]:
    """Nearest neighbour from the ``seeds`` stops nearest the start, each locally improved."""
    n = cost.shape[0] - 1
    firsts = list(np.argsort(cost[0, 1:])[:max(1, min(seeds, n))])
    best, best_t = None, np.inf
    for f in firsts:
        cand = improve(_nearest_neighbour(cost, int(f)), cost)
        t = path_time_s(cand, cost)
        if t < best_t:
            best, best_t = cand, t
    return best or []


def order_from_matrix(cost: NDArray[np.float64]) -> list[int]:
    """Exact when at most :data:`EXACT_MAX` stops, heuristic beyond."""
    n = cost.shape[0] - 1
    if n <= EXACT_MAX:
        return held_karp(cost)
    return heuristic_order(cost)


def order_for_arm(directions: ArrayLike, start: ArrayLike | None, settings: Any) -> list[int]:
    """Permutation of ``range(len(directions))`` minimising total move time from ``start``
    (the lamp's current direction; ``None`` = the park pose)."""
    return order_from_matrix(move_time_matrix(directions, settings, start))
