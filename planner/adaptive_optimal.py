"""A design beyond the homogeneous completions: ``optimal`` conditioned on the lights shot.

Why: with ``--lights N`` an adaptive session chooses among designs that complete the lights
already shot to a homogeneous layout above one floor (``planner.adaptive``). From the shipped
start, the best of those is above the hindsight-tuned homogeneous layout in the cells where
adaptive loses (``benchmarks.adaptive_reach``, docs/adaptive.md). This module builds one more
candidate design: the ``optimal`` planner's objective (:class:`~rti_rig.planner.objectives.
NormalsObjective`, the Lambertian fit's Cramér–Rao bound plus its model bias) over the
*fitted* surface of the images so far (normals, cast shadows of their integrated relief, and
how often this object's fit kept an observation of each kind), minimised by the same exchange
search with the lights already shot kept. Its reach is measured by ``python -m
benchmarks.adaptive_reach --families``, its effect through the chooser by ``python -m
benchmarks.adaptive [--no-fitted-design] [--fitted-pixels K]``. A session offers it beside the
floors with ``planner.adaptive.FITTED_DESIGN`` (on: docs/adaptive.md, "Why the three
losses remain" — it turns two of the three losses into ties and passes the selection rule
searched over 500 pixels; :data:`SEARCH_SCANS` keeps its decision under 0.2 s up to 100
lights; a decision that takes it records ``"design": "fitted"``, format
``rti-rig-adaptive/5``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rti_rig.planner.adaptive import GRAZING_COS, SurfaceState, predicted_weight
from rti_rig.planner.objectives import (
    Candidates,
    NormalsObjective,
    SurfaceSample,
    cast_shadow_visibility,
)
from rti_rig.planner.optimal import MAX_PASSES, exchange_search


class PinnedObjective:
    """An objective over the lights not shot yet: ``fixed`` (candidate indices) are always in
    the layout, never swapped out, and never proposed as a replacement (the exchange search
    sees only the others); ``excluded`` (lights out of service) are never proposed either."""

    def __init__(
        self, objective: Any, fixed: NDArray[np.intp], excluded: NDArray[np.intp] | None = None
    ) -> None:
        self.objective = objective
        self.fixed = np.asarray(fixed, dtype=np.intp)
        self.never = (
            self.fixed if excluded is None else np.union1d(self.fixed, excluded).astype(np.intp)
        )
        self.scan_levels = getattr(objective, "scan_levels", ({"exact": False}, {"exact": True}))
        self.candidate_count = int(objective.candidate_count)

    def cost(self, free: NDArray[np.intp]) -> float:
        return float(self.objective.cost(np.r_[self.fixed, free]))

    def swap_costs(self, free: NDArray[np.intp], position: int, **kw: Any) -> NDArray[np.float64]:
        if kw.get("among") is not None:
            kw["among"] = np.setdiff1d(kw["among"], self.never)
        out = np.array(
            self.objective.swap_costs(np.r_[self.fixed, free], position + len(self.fixed), **kw),
            dtype=np.float64,
        )
        out[self.never] = np.inf
        return out


def pinned_search(
    objective: Any,
    shot: NDArray[np.intp],
    available: NDArray[np.bool_],
    starts: Sequence[NDArray[np.intp]],
) -> NDArray[np.intp]:
    """``optimal``'s exchange search of ``objective`` over the lights not shot (``shot``
    fixed; lights neither shot nor ``available`` never proposed), from the cheapest of
    ``starts`` (completions of the same length), its sweeps capped by :func:`search_passes`.
    Sorted candidate indices."""
    if not starts:
        raise ValueError("the search needs at least one starting completion")
    shot = np.asarray(shot, dtype=np.intp)
    gone = np.setdiff1d(np.flatnonzero(~np.asarray(available, dtype=bool)), shot)
    res = exchange_search(
        PinnedObjective(objective, shot, gone),
        [(str(i), np.asarray(s)) for i, s in enumerate(starts)],
        max_passes=search_passes(len(starts[0])),
    )
    return np.sort(np.asarray(res.chosen, dtype=np.intp))


def state_sample(state: SurfaceState, candidates: NDArray[np.float64]) -> SurfaceSample:
    """The objective's surface sample from the images so far: the fitted normals; a light's
    usefulness for a pixel is its cast-shadow visibility over the relief integrated from the
    fitted normals (when the state has one) times the chance this object's fit keeps such an
    observation (``predicted_weight``'s keep table, without its attached shadow: the
    objective applies its own)."""
    n = state.normals
    cos = n @ candidates.T
    attached = np.clip(cos / GRAZING_COS, 0.0, 1.0)
    keep = np.where(
        attached > 0, predicted_weight(state, candidates) / np.maximum(attached, 1e-9), 1.0
    )
    lit = np.clip(keep, 0.0, 1.0).astype(np.float64)
    if state.height is not None and state.rows is not None and state.cols is not None:
        lit = lit * cast_shadow_visibility(state.height, state.rows, state.cols, candidates)
    p = len(n)
    return SurfaceSample(
        normals=np.asarray(n, dtype=np.float64),
        weights=np.ones(p),
        lit_candidates=lit,
        held_out=np.zeros((0, 3)),
        lit_held_out=np.zeros((p, 0)),
    )


#: At most this many of the state's sampled pixels are searched over (an even sub-sample):
#: the search's cost grows with the pixels (None: all of them, 2000 in a session). 500 ships:
#: chosen leave one scene out against every pixel and against no fitted design at all
#: (docs/adaptive.md, "Why the three losses remain").
SEARCH_PIXELS: int | None = 500
#: A cap on the search's work, so a decision stays under 0.2 s up to 100 lights (each sweep
#: scans every free light's replacements over every searched pixel): with F lights not shot
#: yet, at most ``SEARCH_SCANS // F`` sweeps (1 … ``optimal.MAX_PASSES``) over at most
#: ``SEARCH_SWEEP_WORK // F`` pixels (at least ``SEARCH_MIN_PIXELS``). 56 = 4 sweeps × 14
#: free lights and 7000 = 500 pixels × 14: both bind only beyond 18 lights (from the 4-light
#: start at most 14 are free), where the design is searched more coarsely — it is still
#: taken only if the object's simulation scores it better than the floors by the margin.
SEARCH_SCANS = 56
SEARCH_SWEEP_WORK = 7000
SEARCH_MIN_PIXELS = 100


def _subsample(state: SurfaceState, k: int | None) -> SurfaceState:
    from dataclasses import replace

    p = len(state.normals)
    if k is None or p <= k:
        return state
    pick = np.linspace(0, p - 1, k).round().astype(np.intp)
    return replace(
        state,
        normals=state.normals[pick],
        albedo=state.albedo[pick],
        noise=state.noise[pick],
        lit=state.lit[pick],
        obs=None if state.obs is None else state.obs[:, pick],
        valid=None if state.valid is None else state.valid[pick],
        rows=None if state.rows is None else state.rows[pick],
        cols=None if state.cols is None else state.cols[pick],
        cache={},
    )


def search_passes(free: int) -> int:
    """The sweeps allowed over ``free`` lights not shot yet (:data:`SEARCH_SCANS`)."""
    return int(np.clip(SEARCH_SCANS // max(free, 1), 1, MAX_PASSES))


def search_pixels(free: int) -> int | None:
    """The pixels searched over with ``free`` lights not shot yet (None: all of them):
    :data:`SEARCH_PIXELS`, fewer beyond :data:`SEARCH_SWEEP_WORK` per sweep."""
    if SEARCH_PIXELS is None:
        return None
    return min(SEARCH_PIXELS, max(SEARCH_MIN_PIXELS, SEARCH_SWEEP_WORK // max(free, 1)))


def pinned_optimal_design(
    state: SurfaceState,
    candidates: NDArray[np.float64],
    shot: NDArray[np.intp],
    starts: Sequence[NDArray[np.intp]],
    available: NDArray[np.bool_] | None = None,
) -> NDArray[np.intp]:
    """Candidate indices completing the lights ``shot`` (candidate indices) to the layout of
    least expected error on the fitted surface, searched from each of ``starts`` (completions:
    candidate indices, none of them shot, all of the same length) over the ``available``
    candidates (None: all)."""
    if not starts:
        raise ValueError("the search needs at least one starting completion")
    state = _subsample(state, search_pixels(len(starts[0])))
    sample = state_sample(state, candidates)
    objective = NormalsObjective(sample, Candidates(candidates, None, None))
    if available is None:
        available = np.ones(len(candidates), dtype=bool)
    return pinned_search(objective, shot, available, starts)
