"""The "optimal" method: exchange search over the rig's lights for the chosen objective.

Design of experiments, not clustering: the lights that minimise the expected reconstruction
error over the preview's normals (:mod:`rti_rig.planner.objectives`: Cramér–Rao bound of the
Lambertian fit with attached/cast shadows and highlights removed, or relighting bias² + variance
for the basis the light count supports). The search is a Fedorov-style exchange: start from the
best of several layouts that need no preview (homogeneous layouts with different elevation floors,
plus the k-means layout when given), then sweep over the chosen lights, replacing each by the
unused candidate that lowers the cost most (if any does), until a sweep changes nothing or
gains less than :data:`SWEEP_GAIN` of the cost. A scan scores every unused candidate at once
(for ``normals`` by rank-one updates, :mod:`rti_rig.planner.rank_one`).

Because the starting set includes the homogeneous layout the user would otherwise get and only
improving swaps are accepted, the result is never worse than that layout *on the objective
being optimised* — which is a statement about the model, not about the real surface; the
real-data benchmark (docs/research/planner.md) is where that is checked.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from rti_rig.planner.objectives import NormalsObjective, RelightObjective
from rti_rig.planner.tilt_guard import TiltGuard

#: At most this many sweeps over the chosen lights (a bound on run time; rarely reached).
MAX_PASSES = 4

#: A sweep that lowers the cost by less than this fraction ends the search: on a preview's
#: surface at 100 lights the third and fourth sweeps gained 0.003 % for half the run time
#: (docs/adaptive.md, "adaptive_time").
SWEEP_GAIN = 1e-3


@dataclass(frozen=True)
class ExchangeResult:
    """The chosen candidate indices, their cost, the start's cost and the accepted swaps."""

    chosen: NDArray[np.intp]
    cost: float
    start_cost: float
    start_label: str
    swaps: int
    start_costs: dict[str, float] = field(default_factory=dict)
    #: the tilt (degrees) under which the result keeps its guard (:mod:`rti_rig.planner.tilt_guard`)
    guarded_tilt_deg: float | None = None


def exchange_search(
    objective: NormalsObjective | RelightObjective,
    starts: Sequence[tuple[str, NDArray[np.intp]]],
    max_passes: int | None = None,
    min_gain: float = SWEEP_GAIN,
    search: NormalsObjective | RelightObjective | None = None,
    guard: TiltGuard | None = None,
) -> ExchangeResult:
    """Exchange search from the cheapest of ``starts`` (label, candidate indices).

    Sweeps over the chosen lights; at each, the best replacement among the unused candidates is
    taken if it lowers the cost. Stops after a sweep without a change (a local optimum for
    single swaps), after a sweep that gained less than ``min_gain`` (a fraction of the cost;
    :data:`SWEEP_GAIN` by default, 0 for none) or after :data:`MAX_PASSES` sweeps.

    ``search``: a cheaper stand-in for ``objective`` over the same candidates (its binned
    sample, :mod:`rti_rig.planner.pixel_bins`) that the sweeps score instead. The starts and
    the result are costed on ``objective``; a result that is not cheaper than its start there
    is dropped for the start, so the plan is never worse than its start on ``objective``.

    ``guard``: a :class:`~rti_rig.planner.tilt_guard.TiltGuard` every accepted swap must keep;
    the search then starts from the cheapest start that meets it (and is unguarded, from the
    cheapest of all, if none does).
    """
    if not starts:
        raise ValueError("exchange search needs at least one starting layout")
    costs = {label: objective.cost(np.asarray(s, dtype=np.intp)) for label, s in starts}
    meeting = starts if guard is None else [ls for ls in starts if guard.holds(ls[1])]
    if not meeting:
        meeting, guard = starts, None
    label, first = min(meeting, key=lambda ls: costs[ls[0]])
    chosen = np.asarray(first, dtype=np.intp).copy()
    tilt = None if guard is None else guard.tolerance_deg
    if search is None or search is objective:
        chosen, cost, swaps = _sweeps(objective, chosen, costs[label], max_passes, min_gain, guard)
        return ExchangeResult(chosen, cost, costs[label], label, swaps, costs, tilt)
    chosen, _, swaps = _sweeps(search, chosen, search.cost(chosen), max_passes, min_gain, guard)
    cost = objective.cost(chosen)
    if not cost < costs[label]:
        chosen, cost, swaps = np.asarray(first, dtype=np.intp).copy(), costs[label], 0
    return ExchangeResult(chosen, cost, costs[label], label, swaps, costs, tilt)


def _sweeps(
    objective: NormalsObjective | RelightObjective,
    chosen: NDArray[np.intp],
    cost: float,
    max_passes: int | None,
    min_gain: float,
    guard: TiltGuard | None = None,
) -> tuple[NDArray[np.intp], float, int]:
    """The sweeps of :func:`exchange_search` from ``chosen`` (of cost ``cost``): the layout,
    its cost and the swaps accepted; with a ``guard``, only swaps that keep it."""
    n = len(chosen)
    limit = max_passes if max_passes is not None else MAX_PASSES
    swaps = 0
    # only the unused candidates can replace a light (a light is never chosen twice): an
    # objective that knows its candidate count scores only those (half of them at 100 of 200)
    count = getattr(objective, "candidate_count", None)
    levels = getattr(objective, "scan_levels", ({"exact": False}, {"exact": True}))
    # an objective that can skip the candidates proved not to beat the current cost is told
    # it (the same argmin whenever one beats it: the rest are inf, proved not to)
    bounded = bool(getattr(objective, "bounded_scans", False))
    unused = None if count is None else np.ones(count, dtype=bool)
    if unused is not None:
        unused[chosen] = False
    # positions known to have no improving swap in the current layout (the one just swapped
    # counts: its scan saw the same other lights): at n the layout is a local optimum for
    # single swaps, and the rest of the sweep and the confirming sweep after it would find
    # nothing — the same plan, fewer scans
    idle = 0
    for _ in range(limit):
        changed = False
        before = cost
        for pos in range(n):
            if idle >= n:
                break
            idle += 1
            scan_kw = {} if unused is None else {"among": np.flatnonzero(unused)}
            barred = None if guard is None else ~guard.allowed(chosen, pos)
            for level in levels:
                # the fast scan may be approximate (rank-one updates, single precision): a swap
                # is accepted on its exact cost, and a proposal that cost does not confirm
                # earns a re-scan at the next level (the last: every pixel evaluated directly)
                target = cost - 1e-9 * max(abs(cost), 1e-12)
                bound_kw = {"below": target} if bounded else {}
                trial = objective.swap_costs(chosen, pos, **level, **scan_kw, **bound_kw)
                trial[chosen] = np.inf  # no repeats (the current light itself is "no change")
                if barred is not None:
                    trial[barred] = np.inf  # the swaps that would break the tilt guard
                k = int(np.argmin(trial))
                if not float(trial[k]) < target:
                    break  # no improving swap at this position
                previous = int(chosen[pos])
                chosen[pos] = k
                exact = objective.cost(chosen)
                if exact < cost - 1e-9 * max(abs(cost), 1e-12):
                    if unused is not None:
                        unused[previous], unused[k] = True, False
                    cost = exact
                    swaps += 1
                    changed = True
                    idle = 1
                    break
                chosen[pos] = previous
        if not changed or idle >= n or before - cost < min_gain * abs(before):
            break
    return chosen, cost, swaps
