"""The adaptive chooser (planner/adaptive.py): its bound, its rank-one update, its choices."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from rti_rig.core.geometry import direction_from_az_el, fibonacci_cap
from rti_rig.planner.adaptive import (
    MAX_ERR2,
    bound_error2,
    choose_next,
    estimate_error_deg,
    predicted_error2,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from adaptive_states import state_for


def test_bound_matches_the_closed_form_for_an_orthogonal_ring() -> None:
    """Algorithms notes §3: N lights at slant 54.74° equally spaced give L^T L = (N/3) I, so
    E[θ²] = 6 σ²/N for a level normal."""
    n = 6
    el = 90.0 - np.degrees(np.arccos(1 / np.sqrt(3)))
    lights = direction_from_az_el(np.arange(n) * 360.0 / n, np.full(n, el))
    st = state_for(np.array([[0.0, 0.0, 1.0]]), lights, noise=0.01)
    np.testing.assert_allclose(bound_error2(st), [6 * 0.01**2 / n], rtol=1e-3)


def test_rank_one_update_equals_refitting_with_the_light_added() -> None:
    rng = np.random.default_rng(3)
    normals = fibonacci_cap(40, 30.0)
    lights = fibonacci_cap(5, 20.0)
    st = state_for(normals, lights)
    cands = fibonacci_cap(30, 5.0)
    got = predicted_error2(st, cands)
    for c in rng.choice(len(cands), 6, replace=False):
        l_new = np.vstack([lights, cands[c]])
        cos = normals @ cands[c]
        w = np.clip(cos / 0.15, 0.0, 1.0)
        # the same state with light c added, weighted as the predictor weighs it
        lit = np.hstack([st.lit, (w > 0)[:, None]]).astype(float)
        lit[:, -1] = w
        m = np.einsum("pk,ki,kj->pij", lit, l_new, l_new) + 1e-4 * np.eye(3)
        minv = np.linalg.inv(m)
        t = np.trace(minv, axis1=1, axis2=2) - np.einsum("pi,pij,pj->p", normals, minv, normals)
        want = np.minimum((0.01**2) * t, MAX_ERR2)
        np.testing.assert_allclose(got[:, c], want, rtol=2e-3, atol=1e-12)


def test_it_lights_what_the_first_lights_left_unobservable() -> None:
    """Three lights from one side leave normals tilted the other way in shadow; the next light
    is chosen from the other side."""
    lights = direction_from_az_el(np.array([0.0, 30.0, -30.0]), np.full(3, 30.0))
    normals = np.vstack([fibonacci_cap(30, 60.0), direction_from_az_el(180.0, 30.0)[None]])
    st = state_for(normals, lights)
    cands = direction_from_az_el(np.arange(0.0, 360.0, 30.0), np.full(12, 30.0))
    d = choose_next(st, cands, np.ones(12, dtype=bool))
    assert d.candidate is not None
    az = np.degrees(np.arctan2(cands[d.candidate, 1], cands[d.candidate, 0])) % 360
    assert 90 < az < 270
    assert d.predicted_error_deg < d.estimated_error_deg


def test_move_time_steers_the_choice_and_unavailable_lights_are_never_chosen() -> None:
    normals = fibonacci_cap(50, 40.0)
    lights = fibonacci_cap(4, 25.0)
    st = state_for(normals, lights)
    cands = fibonacci_cap(40, 5.0)
    free = choose_next(st, cands, np.ones(40, dtype=bool))
    move = np.full(40, 0.0)
    move[free.candidate] = 50.0  # the best light is far away on an arm
    slow = choose_next(st, cands, np.ones(40, dtype=bool), capture_s=1.0, move_s=move)
    assert slow.candidate != free.candidate
    avail = np.ones(40, dtype=bool)
    avail[free.candidate] = False
    other = choose_next(st, cands, avail)
    assert other.candidate != free.candidate
    assert choose_next(st, cands, np.zeros(40, dtype=bool)).candidate is None


def test_decisions_are_deterministic_and_the_estimate_scales() -> None:
    normals = fibonacci_cap(60, 35.0)
    st = state_for(normals, fibonacci_cap(5, 20.0))
    cands = fibonacci_cap(30, 5.0)
    a = choose_next(st, cands, np.ones(30, dtype=bool))
    b = choose_next(st, cands, np.ones(30, dtype=bool))
    assert a == b
    assert estimate_error_deg(st, 2.0) == pytest.approx(2 * estimate_error_deg(st, 1.0))
