"""Motion-time model and move ordering."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from dxl_support import arm_settings
from hypothesis import given, settings
from hypothesis import strategies as st

from rti_rig.core.arm_motion import joint_move_time_s, move_time_matrix, move_time_s
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.planner.arm_order import (
    EXACT_MAX,
    NEIGHBOURS,
    _or_opt,
    _two_opt,
    held_karp,
    heuristic_order,
    neighbour_lists,
    order_for_arm,
    order_from_matrix,
    path_time_s,
)


def test_trapezoid_and_triangle() -> None:
    # 90 deg at 45 deg/s, 90 deg/s^2: accel 0.5 s over 11.25 deg, cruise, decel -> 2.5 s
    assert joint_move_time_s(90.0, 45.0, 90.0) == pytest.approx(2.5)
    # too short to reach cruise: triangle 2*sqrt(d/a)
    assert joint_move_time_s(10.0, 45.0, 90.0) == pytest.approx(2 * math.sqrt(10 / 90))
    assert joint_move_time_s(0.0, 45.0, 90.0) == 0.0
    # continuous at the switch-over distance v^2/a
    d = 45.0**2 / 90.0
    assert joint_move_time_s(d - 1e-9, 45, 90) == pytest.approx(joint_move_time_s(d, 45, 90))


def test_slower_joint_sets_the_pace_and_matrix_agrees() -> None:
    s = arm_settings(settle_time_s=0.1, elevation=dict(profile_velocity_rpm=5.0))
    a, b = direction_from_az_el(0, 10), direction_from_az_el(5, 60)
    el = s.elevation
    t_el = joint_move_time_s(50.0, el.joint_velocity_deg_s, el.joint_acceleration_deg_s2)
    assert move_time_s(a, b, s) == pytest.approx(t_el + 0.1)
    dirs = direction_from_az_el(np.array([10, -100, 150]), np.array([20, 50, 5]))
    m = move_time_matrix(dirs, s, start=a)
    for i in range(3):
        assert m[0, i + 1] == pytest.approx(move_time_s(a, dirs[i], s))
        for j in range(3):
            if i != j:
                assert m[i + 1, j + 1] == pytest.approx(move_time_s(dirs[i], dirs[j], s))


@settings(max_examples=25, deadline=None)
@given(st.integers(1, 7), st.integers(0, 2**32 - 1))
def test_held_karp_equals_brute_force(n: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    cost = rng.uniform(0.1, 5.0, size=(n + 1, n + 1))  # asymmetric on purpose
    best = min(path_time_s(list(p), cost) for p in itertools.permutations(range(n)))
    order = held_karp(cost)
    assert sorted(order) == list(range(n))
    assert path_time_s(order, cost) == pytest.approx(best)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6))
def test_heuristic_is_within_3_percent_of_optimal(seed: int) -> None:
    rng = np.random.default_rng(seed)
    s = arm_settings()
    n = 12
    dirs = direction_from_az_el(rng.uniform(-170, 170, n), rng.uniform(0, 75, n))
    cost = move_time_matrix(dirs, s)
    exact = path_time_s(held_karp(cost), cost)
    heur = path_time_s(heuristic_order(cost), cost)
    assert exact <= heur + 1e-9
    assert heur <= 1.03 * exact


@pytest.mark.slow
def test_order_for_arm_beats_plan_order_and_is_a_permutation() -> None:
    rng = np.random.default_rng(7)
    s = arm_settings()
    for n in (5, EXACT_MAX, 40):
        dirs = direction_from_az_el(rng.uniform(-170, 170, n), rng.uniform(0, 75, n))
        order = order_for_arm(dirs, None, s)
        assert sorted(order) == list(range(n))
        cost = move_time_matrix(dirs, s)
        assert path_time_s(order, cost) < path_time_s(list(range(n)), cost)
    assert order_from_matrix(np.zeros((1, 1))) == []


def test_sequence_time_follows_multi_turn_choices() -> None:
    from rti_rig.core.arm_motion import sequence_time_s

    s = arm_settings(
        azimuth=dict(operating_mode="extended_position", min_deg=-360.0, max_deg=360.0),
        settle_time_s=0.0,
    )
    dirs = direction_from_az_el(np.array([170.0, -170.0]), np.array([10.0, 10.0]))
    # from park (az 0, el 10): 170 deg, then -170 is joint 190 deg: 20 deg the short way
    az = s.azimuth
    t = lambda d: joint_move_time_s(d, az.joint_velocity_deg_s, az.joint_acceleration_deg_s2)  # noqa: E731
    assert sequence_time_s(dirs, s) == pytest.approx(t(170.0) + t(20.0))
    # the pairwise matrix fixes each stop's azimuth nearest the start: 340 deg apart
    m = move_time_matrix(dirs, s)
    assert m[1, 2] == pytest.approx(t(340.0))


@pytest.mark.slow
def test_multi_turn_ordering_uses_the_short_way_when_it_helps() -> None:
    from rti_rig.core.arm_motion import sequence_time_s

    s = arm_settings(
        azimuth=dict(operating_mode="extended_position", min_deg=-540.0, max_deg=540.0)
    )
    rng = np.random.default_rng(3)
    az = rng.uniform(-180, 180, 20)
    dirs = direction_from_az_el(az, rng.uniform(5, 70, 20))
    order = order_for_arm(dirs, None, s)
    assert sorted(order) == list(range(20))
    fixed = order_from_matrix(move_time_matrix(dirs, s))
    cyclic = order_from_matrix(move_time_matrix(dirs, s, cyclic=True))
    t = sequence_time_s(dirs[order], s)
    best = min(sequence_time_s(dirs[fixed], s), sequence_time_s(dirs[cyclic], s))
    assert t == pytest.approx(best)
    assert t < sequence_time_s(dirs, s)


def _or_opt_one_at_a_time(nodes: list[int], cost: np.ndarray) -> tuple[list[int], bool]:
    """The Or-opt pass as it was written first: each segment examined on its own, in order."""
    improved = False
    for seg in (1, 2, 3):
        i = 1
        while i + seg <= len(nodes):
            s = nodes[i : i + seg]
            p = nodes[i - 1]
            q = nodes[i + seg] if i + seg < len(nodes) else None
            removed = cost[p, s[0]] + (cost[s[-1], q] if q is not None else 0.0)
            bridged = cost[p, q] if q is not None else 0.0
            inner_f = sum(cost[s[t], s[t + 1]] for t in range(seg - 1))
            inner_b = sum(cost[s[t + 1], s[t]] for t in range(seg - 1))
            rest = np.asarray(nodes[:i] + nodes[i + seg :])
            y = np.append(rest[1:], -1)
            has_y = y >= 0
            y_safe = np.where(has_y, y, 0)
            opened = np.where(has_y, cost[rest, y_safe], 0.0)
            best_delta, best_move = -1e-12, None
            ways = ((False, s[0], s[-1], inner_f), (True, s[-1], s[0], inner_b))
            for rev, first, last, inner in ways:
                added = cost[rest, first] + np.where(has_y, cost[last, y_safe], 0.0)
                delta = (bridged - removed) + (added - opened) + (inner - inner_f)
                delta[i - 1] = np.inf
                j = int(np.argmin(delta))
                if delta[j] < best_delta:
                    best_delta, best_move = float(delta[j]), (j + 1, rev)
            if best_move is not None:
                pos, rev = best_move
                rest_l = rest.tolist()
                nodes = rest_l[:pos] + (s[::-1] if rev else s) + rest_l[pos:]
                improved = True
            else:
                i += 1
    return nodes, improved


@pytest.mark.parametrize("seed", range(4))
def test_or_opt_makes_the_moves_of_the_one_at_a_time_pass(seed: int) -> None:
    """The vectorised Or-opt (all segments' deltas at once) moves exactly as the loop did,
    ties included (rounded costs), on asymmetric matrices of 2 to 60 stops."""
    rng = np.random.default_rng(seed)
    for trial in range(40):
        n = int(rng.integers(1, 60))
        cost = rng.random((n + 1, n + 1)) * 10.0
        if trial % 2:
            cost = np.round(cost)
        nodes = [0, *(int(v) for v in rng.permutation(np.arange(1, n + 1)))]
        assert _or_opt(list(nodes), cost) == _or_opt_one_at_a_time(list(nodes), cost)


def _two_opt_one_at_a_time(nodes: list[int], cost: np.ndarray) -> tuple[list[int], bool]:
    """The 2-opt pass as it was written first: each segment start examined on its own."""
    improved = False
    m = len(nodes)
    i = 1
    while i < m - 1:
        arr = np.asarray(nodes)
        fwd = np.concatenate([[0.0], np.cumsum(cost[arr[:-1], arr[1:]])])
        bwd = np.concatenate([[0.0], np.cumsum(cost[arr[1:], arr[:-1]])])
        a, b = arr[i - 1], arr[i]
        ks = np.arange(i + 1, m)
        c = arr[ks]
        delta = cost[a, c] - cost[a, b] + (bwd[ks] - bwd[i]) - (fwd[ks] - fwd[i])
        has_d = ks + 1 < m
        d = arr[np.minimum(ks + 1, m - 1)]
        delta = delta + np.where(has_d, cost[b, d] - cost[c, d], 0.0)
        best = int(np.argmin(delta))
        if delta[best] < -1e-12:
            k = int(ks[best])
            nodes = nodes[:i] + nodes[i : k + 1][::-1] + nodes[k + 1 :]
            improved = True
        else:
            i += 1
    return nodes, improved


@pytest.mark.parametrize("seed", range(4))
def test_two_opt_makes_the_moves_of_the_one_at_a_time_pass(seed: int) -> None:
    """The vectorised 2-opt (every segment start's deltas at once) reverses exactly as the loop
    did, ties included (rounded costs), on asymmetric matrices of 1 to 120 stops."""
    rng = np.random.default_rng(seed)
    moved = 0
    for trial in range(40):
        n = int(rng.integers(1, 120))
        cost = rng.random((n + 1, n + 1)) * 10.0
        if trial % 2:
            cost = np.round(cost)
        nodes = [0, *(int(v) for v in rng.permutation(np.arange(1, n + 1)))]
        got = _two_opt(list(nodes), cost)
        assert got == _two_opt_one_at_a_time(list(nodes), cost)
        moved += got[1]
    assert moved >= 30  # random paths: the pass had reversals to make


def test_arm_order_of_a_hundred_planned_lights_is_the_one_the_loops_gave(monkeypatch) -> None:
    """On a servo arm's move times at 100 stops, the whole heuristic (nearest neighbour, 2-opt,
    Or-opt, kicks) gives the same order with the vectorised passes as with the loops."""
    from rti_rig.planner import arm_order

    s = arm_settings()
    rng = np.random.default_rng(5)
    az, el = rng.uniform(-170.0, 170.0, 100), rng.uniform(0.0, 75.0, 100)
    dirs = np.array([direction_from_az_el(a, e) for a, e in zip(az, el, strict=True)])
    fast = order_for_arm(dirs, None, s)

    def exhaustive(loop):  # the loops know no neighbour lists: 100 stops search them all
        def run(nodes: list[int], cost: np.ndarray, near: object = None):
            assert near is None
            return loop(nodes, cost)

        return run

    monkeypatch.setattr(arm_order, "_two_opt", exhaustive(_two_opt_one_at_a_time))
    monkeypatch.setattr(arm_order, "_or_opt", exhaustive(_or_opt_one_at_a_time))
    assert fast == order_for_arm(dirs, None, s)


@pytest.mark.parametrize("seed", range(2))
def test_neighbour_list_passes_make_the_exhaustive_moves_when_every_stop_is_a_neighbour(
    seed: int,
) -> None:
    """The neighbour-list 2-opt and Or-opt (candidate columns from the lists, rows in chunks)
    compute the same deltas as the exhaustive passes: with lists holding every stop they make
    the same moves, on asymmetric matrices of 2 to 90 stops (more than one chunk of rows)."""
    rng = np.random.default_rng(100 + seed)
    for _ in range(6):
        n = int(rng.integers(2, 90))
        cost = rng.random((n + 1, n + 1)) * 10.0
        near = neighbour_lists(cost, n)
        nodes = [0, *(int(v) for v in rng.permutation(np.arange(1, n + 1)))]
        assert _two_opt(list(nodes), cost, near) == _two_opt(list(nodes), cost)
        assert _or_opt(list(nodes), cost, near) == _or_opt(list(nodes), cost)


def test_neighbour_lists_keep_the_arm_order_within_half_a_percent_of_the_full_search() -> None:
    """Above FULL_SEARCH_MAX the search tries moves to each stop's NEIGHBOURS nearest only; on
    an arm's move times its order takes no more than 0.5 % longer than the full search's."""
    s = arm_settings()
    rng = np.random.default_rng(11)
    n = 120
    dirs = direction_from_az_el(rng.uniform(-170.0, 170.0, n), rng.uniform(5.0, 70.0, n))
    cost = move_time_matrix(dirs, s)
    fast = heuristic_order(cost, kicks=5, neighbours=NEIGHBOURS)
    full = heuristic_order(cost, kicks=5, neighbours=0)
    assert sorted(fast) == list(range(n))
    assert path_time_s(fast, cost) <= 1.005 * path_time_s(full, cost)
