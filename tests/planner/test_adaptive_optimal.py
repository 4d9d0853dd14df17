"""`optimal` conditioned on the lights shot (planner.adaptive_optimal): measured as a design
family by benchmarks.adaptive_reach --families; these tests pin what it must guarantee."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.adaptive import homogeneous_completion, start_subset
from rti_rig.planner.adaptive_optimal import (
    PinnedObjective,
    pinned_optimal_design,
    state_sample,
)
from rti_rig.planner.objectives import Candidates, NormalsObjective
from rti_rig.planner.optimal import exchange_search
from rti_rig.planner.uniform import select_uniform_leds

sys.path.insert(0, str(Path(__file__).resolve().parent))
from adaptive_states import state_for


def _setup(n_total: int = 9, tilt: float = 0.0):  # type: ignore[no-untyped-def]
    dirs = fibonacci_cap(120, 3.0)
    g = DomeGeometry(dirs, tuple(f"l{i}" for i in range(len(dirs))))
    full = select_uniform_leds(g, n_total, 10.0)
    shot = np.array([int(full[i]) for i in start_subset(dirs[full], 4)])
    rng = np.random.default_rng(0)
    normals = np.c_[rng.normal(0, 0.3, (200, 2)), np.ones(200)]
    normals[:, 0] += tilt
    state = state_for(normals, dirs[shot])
    available = np.ones(len(dirs), bool)
    available[shot] = False
    starts = [
        homogeneous_completion(dirs, available, dirs[shot], n_total, f) for f in (0.0, 10.0, 20.0)
    ]
    return dirs, shot, state, starts


def test_the_design_completes_the_shot_lights_without_repeating_any() -> None:
    dirs, shot, state, starts = _setup()
    free = pinned_optimal_design(state, dirs, shot, starts)
    assert len(free) == 9 - len(shot)
    assert len(set(free.tolist())) == len(free)
    assert not set(free.tolist()) & set(shot.tolist())


def test_it_is_never_worse_on_its_objective_than_the_completions_it_starts_from() -> None:
    dirs, shot, state, starts = _setup(tilt=0.6)  # a tilted surface: the floors differ
    free = pinned_optimal_design(state, dirs, shot, starts)
    objective = NormalsObjective(state_sample(state, dirs), Candidates(dirs, None, None))
    got = objective.cost(np.r_[shot, free])
    assert got <= min(objective.cost(np.r_[shot, s]) for s in starts) + 1e-12


def test_the_pinned_objective_never_proposes_or_moves_a_shot_light() -> None:
    dirs, shot, state, starts = _setup()
    objective = NormalsObjective(state_sample(state, dirs), Candidates(dirs, None, None))
    pinned = PinnedObjective(objective, shot)
    costs = pinned.swap_costs(np.asarray(starts[1]), 0)
    assert np.isinf(costs[shot]).all()
    assert np.isfinite(costs).sum() > 0
    # unpinned, the same search is free to drop a shot light: the wrapper is what keeps them
    res = exchange_search(pinned, [("s", np.asarray(starts[0]))])
    assert not set(res.chosen.tolist()) & set(shot.tolist())


def test_lights_out_of_service_are_never_proposed_and_the_design_is_kept() -> None:
    """The lights the search would take, put out of service: it completes the design with
    others instead (the fitted design was dropped whenever its search wandered onto one)."""
    dirs, shot, state, starts = _setup(tilt=0.6)
    free = pinned_optimal_design(state, dirs, shot, starts)
    available = np.ones(len(dirs), bool)
    available[shot] = False
    out = np.setdiff1d(free, np.concatenate(starts))  # chosen by the search, in no start
    assert out.size  # the premise: the search leaves the starts
    available[out] = False
    again = pinned_optimal_design(state, dirs, shot, starts, available)
    assert len(again) == len(free) and available[again].all()


def test_cast_shadows_and_the_keep_table_lower_a_light_s_use() -> None:
    """The sample's lit factor is 1 for a light the fit keeps on a flat relief, and a ridge of
    relief casting a shadow takes it to 0 for the pixels behind it."""
    dirs, _, state, _ = _setup()
    flat = state_sample(state, dirs)
    assert flat.lit_candidates.shape == (len(state.normals), len(dirs))
    assert np.all((flat.lit_candidates >= 0) & (flat.lit_candidates <= 1))
    from dataclasses import replace

    height = np.zeros((20, 20))
    height[:, 10] = 50.0  # a wall along the column 10
    rows = np.full(len(state.normals), 10)
    cols = np.full(len(state.normals), 12)  # just east of the wall
    walled = state_sample(replace(state, height=height, rows=rows, cols=cols), dirs)
    west_low = (dirs[:, 0] < -0.9) & (dirs[:, 2] < 0.3)
    assert west_low.any()
    assert np.all(flat.lit_candidates[:, west_low] > 0)  # no relief: nothing casts a shadow
    assert np.all(walled.lit_candidates[:, west_low] == 0)


def _session(n_total: int) -> list[dict]:  # type: ignore[type-arg]
    """The chooser's evidence over a session of ``n_total`` on a Lambertian bumpy surface."""
    from rti_rig.app.usecases.adaptive import AdaptiveChooser, dome_start

    dirs = fibonacci_cap(120, 3.0)
    g = DomeGeometry(dirs, tuple(f"l{i}" for i in range(len(dirs))))
    yy, xx = np.mgrid[0:48, 0:48] / 48.0
    normals = np.dstack([0.5 * np.sin(6 * xx), 0.4 * np.cos(5 * yy), np.ones_like(xx)])
    normals /= np.linalg.norm(normals, axis=2, keepdims=True)
    images = np.clip(np.einsum("hwc,kc->khw", normals, dirs), 0.0, None).astype(np.float32)
    chooser = AdaptiveChooser(dirs, dome_start(g, 4, n_total), n_total, design_lights=n_total)
    evidence = []
    for i in range(n_total + 1):
        c, ev = chooser.decide(i)
        evidence.append(ev)
        if c is None:
            break
        chooser.observe(c, dirs[c], images[c])
    assert len(chooser.used) == n_total == len(set(chooser.used))
    return evidence


def test_by_default_the_fitted_design_is_scored_beside_the_floors() -> None:
    evidence = [e for e in _session(6) if e.get("kind") == "adaptive"]
    assert evidence and all("fitted" in e["design_error_deg"] for e in evidence)
    # a decision names either a floor or the fitted design, never both
    assert all(("design" in e) != ("design_floor_deg" in e) for e in evidence)


def test_turned_off_the_decisions_offer_only_floors(monkeypatch: pytest.MonkeyPatch) -> None:
    import rti_rig.planner.adaptive as adaptive

    monkeypatch.setattr(adaptive, "FITTED_DESIGN", False)
    evidence = [e for e in _session(6) if e.get("kind") == "adaptive"]
    assert evidence and all("design_floor_deg" in e for e in evidence)
    assert all("fitted" not in e["design_error_deg"] for e in evidence)


def test_the_search_s_cap_binds_only_beyond_18_lights() -> None:
    """From the 4-light start at most 14 lights are free at N <= 18: every sweep allowed
    there (the decisions unchanged); beyond, fewer sweeps, at least one."""
    from rti_rig.planner.adaptive import START_LIGHTS
    from rti_rig.planner.adaptive_optimal import search_passes
    from rti_rig.planner.optimal import MAX_PASSES

    assert all(search_passes(f) == MAX_PASSES for f in range(1, 18 - START_LIGHTS + 1))
    assert search_passes(20) < MAX_PASSES
    assert search_passes(50) == search_passes(96) == 1


def test_the_search_s_pixels_shrink_only_beyond_18_lights() -> None:
    from rti_rig.planner.adaptive import START_LIGHTS
    from rti_rig.planner.adaptive_optimal import SEARCH_PIXELS, search_pixels

    assert SEARCH_PIXELS == 500  # what was chosen leave one scene out
    assert all(search_pixels(f) == SEARCH_PIXELS for f in range(1, 18 - START_LIGHTS + 1))
    assert 100 <= search_pixels(50) < SEARCH_PIXELS and search_pixels(96) == 100


def test_at_100_lights_the_search_scans_each_free_light_about_once(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The cap is what bounds a decision's time at large N: the single-light scans of the
    search, counted, stay within one sweep (plus the re-scans of a proposal) at 100 lights."""
    dirs = fibonacci_cap(200, 5.0)
    g = DomeGeometry(dirs, tuple(f"l{i}" for i in range(len(dirs))))
    full = select_uniform_leds(g, 100, 10.0)
    shot = np.array([int(full[i]) for i in start_subset(dirs[full], 50)])
    rng = np.random.default_rng(1)
    normals = np.c_[rng.normal(0, 0.4, (300, 2)), np.ones(300)]
    state = state_for(normals, dirs[shot])
    available = np.ones(len(dirs), bool)
    available[shot] = False
    starts = [
        homogeneous_completion(dirs, available, dirs[shot], 100, f) for f in (0.0, 10.0, 20.0)
    ]
    calls = []
    real = NormalsObjective.swap_costs

    def counted(self, *a, **kw):  # type: ignore[no-untyped-def]
        calls.append(kw.get("exact"))
        return real(self, *a, **kw)

    monkeypatch.setattr(NormalsObjective, "swap_costs", counted)
    free = pinned_optimal_design(state, dirs, shot, starts)
    assert len(free) == 50 and not set(free.tolist()) & set(shot.tolist())
    assert sum(1 for c in calls if not c) <= 50


def test_a_pixel_sub_sample_keeps_every_per_pixel_array_aligned(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import rti_rig.planner.adaptive_optimal as adaptive_optimal

    dirs, shot, state, starts = _setup()
    small = adaptive_optimal._subsample(state, 50)
    assert len(small.normals) == len(small.albedo) == len(small.noise) == len(small.lit) == 50
    assert np.array_equal(small.normals[0], state.normals[0])
    assert np.array_equal(small.normals[-1], state.normals[-1])
    assert adaptive_optimal._subsample(state, 10_000) is state
    monkeypatch.setattr(adaptive_optimal, "SEARCH_PIXELS", 50)
    free = pinned_optimal_design(state, dirs, shot, starts)
    assert len(free) == 9 - len(shot) and not set(free.tolist()) & set(shot.tolist())


def _old_rule(scores: dict[float, float], keep: float, margin: float) -> float:
    """The selection before FITTED_MARGIN: the best design if it beats ``keep`` by ``margin``."""
    best = min(scores, key=lambda f: (scores[f], abs(f - keep)))
    if keep in scores and scores[keep] <= (1.0 + margin) * scores[best]:
        best = keep
    return best


@pytest.mark.parametrize("seed", range(40))
def test_one_margin_for_every_design_is_the_rule_that_ships(seed: int) -> None:
    from rti_rig.planner.adaptive import FITTED_KEY, _switch

    rng = np.random.default_rng(seed)
    keys = [FITTED_KEY, 0.0, 10.0, 20.0, 30.0]
    scores = {k: float(v) for k, v in zip(keys, 1.0 + 0.2 * rng.random(5), strict=True)}
    if seed % 4 == 0:  # ties
        scores[20.0] = scores[10.0]
    keep = [10.0, 20.0, FITTED_KEY, 5.0][seed % 4]  # 5: not among the designs
    assert _switch(scores, keep, 0.1, None) == _old_rule(scores, keep, 0.1)
    assert _switch(scores, keep, 0.1, 0.1) == _old_rule(scores, keep, 0.1)


def test_a_larger_margin_for_the_fitted_design_lets_a_floor_that_passes_its_own_win() -> None:
    from rti_rig.planner.adaptive import FITTED_KEY, _switch

    scores = {FITTED_KEY: 0.80, 10.0: 1.00, 20.0: 0.85}
    assert _switch(scores, 10.0, 0.1, None) == FITTED_KEY
    assert _switch(scores, 10.0, 0.1, 0.3) == 20.0  # the fitted design short of its margin
    assert _switch(scores, 10.0, 0.2, 0.3) == 10.0  # and the floor short of its own
    assert _switch(scores, 20.0, 0.1, 0.01) == FITTED_KEY  # a smaller margin for the fitted


def test_extra_seed_floors_only_add_starts_to_the_fitted_search(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """FITTED_SEED_FLOORS seeds the search with more completions (the search starts from the
    cheapest of them on its objective), one per floor."""
    import rti_rig.planner.adaptive as adaptive
    import rti_rig.planner.adaptive_optimal as adaptive_optimal

    seen: list[int] = []
    real = adaptive_optimal.pinned_optimal_design

    def spy(state, candidates, shot, starts, available=None):  # type: ignore[no-untyped-def]
        seen.append(len(starts))
        return real(state, candidates, shot, starts, available)

    monkeypatch.setattr(adaptive_optimal, "pinned_optimal_design", spy)
    monkeypatch.setattr(adaptive, "FITTED_SEED_FLOORS", ())
    _session(9)
    plain = list(seen)
    seen.clear()
    monkeypatch.setattr(adaptive, "FITTED_SEED_FLOORS", (5.0, 15.0))
    _session(9)
    assert plain and len(seen) == len(plain)
    assert all(b == a + 2 for a, b in zip(plain, seen, strict=True))
