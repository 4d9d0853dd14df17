"""The three built-in planning methods: ``uniform``, ``kmeans`` (the paper's) and ``optimal``.

Each is a thin adapter from the planner's pipeline (:mod:`rti_rig.planner.make_plan`) to the
module that does the work: :mod:`rti_rig.planner.uniform`, :mod:`rti_rig.planner.kmeans_method`,
:mod:`rti_rig.planner.optimal`. Importing this module registers them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.planner import tilt_guard as tilt_guard_module
from rti_rig.planner.kmeans_method import plan_kmeans
from rti_rig.planner.methods import MethodContext, SurfaceNeed, register_method
from rti_rig.planner.objectives import NormalsObjective, RelightObjective
from rti_rig.planner.optimal import exchange_search
from rti_rig.planner.pixel_bins import binned_objective
from rti_rig.planner.tilt_guard import TiltGuard, object_plane, tilt_guard

#: Below this many lights the exchange search is not run: 3 lights are exactly the unknowns of
#: the Lambertian fit, with no redundancy left for a shadow or a highlight.
MIN_LIGHTS_FOR_EXCHANGE = 4

#: From this light count up the benchmarks found the ``optimal`` normals plan's gain over a
#: homogeneous layout small and object-dependent (real dome: a tie at 12 lights and −0.39° at 18
#: by default, wins at both declared glossy; simulator: losses on brushed steel at 20 and 30
#: against a 10° floor), so the report says so.
MANY_LIGHTS = 12


def _score_start(ctx: MethodContext, objective: NormalsObjective | RelightObjective) -> None:
    """Record the expected error of the homogeneous layout at the user's floor (the baseline
    every report shows)."""
    label, start = ctx.starts[0]
    ctx.report.expected[label] = objective.cost(start)


@dataclass(frozen=True)
class UniformMethod:
    """The homogeneous layout at the user's floor; a preview is only scored against."""

    name: str = "uniform"
    summary: str = "homogeneous, no preview"
    surface: SurfaceNeed = "none"
    needs_preview_reason: str = ""
    optimises_objective: bool = False

    def prepare(self, ctx: MethodContext) -> NDArray[np.intp]:
        return ctx.starts[0][1]

    def decide(
        self,
        ctx: MethodContext,
        objective: NormalsObjective | RelightObjective,
        chosen: NDArray[np.intp],
    ) -> NDArray[np.intp]:
        _score_start(ctx, objective)
        return chosen


@dataclass(frozen=True)
class KMeansMethod:
    """The paper's method: the usable positions nearest the preview's normal clusters."""

    name: str = "kmeans"
    summary: str = "the paper's: k-means on the preview's normals"
    surface: SurfaceNeed = "preview"
    needs_preview_reason: str = (
        "--method kmeans clusters the preview's normals: give PREVIEW (a preview shot), or "
        "use --method optimal (which plans for a flat surface without one) or uniform"
    )
    optimises_objective: bool = False

    def prepare(self, ctx: MethodContext) -> NDArray[np.intp]:
        # the paper clusters the depth gradient's normals as they come: no shrinkage
        surface, report = ctx.surface, ctx.report
        assert surface is not None  # surface = "preview": the request's check saw to it
        raw = surface.fitted_normals if surface.fitted_normals is not None else surface.normals
        chosen, km = plan_kmeans(raw, ctx.n, ctx.candidates, ctx.seed)
        report.kmeans_distinct_normals = km.distinct_normals
        if ctx.ceiling_cuts:
            report.notes.append(
                f"kmeans puts each light at the usable position nearest its cluster centre: "
                f"under the {ctx.max_elevation_deg:g}° ceiling the clusters of a near-level "
                "surface all land on the ceiling's ring"
            )
        if km.distinct_normals < ctx.n:
            report.notes.append(
                f"only {km.distinct_normals} distinct normals for {ctx.n} clusters: the "
                "remaining lights sit on the usable positions nearest the cluster centres"
            )
        ctx.starts.append(("kmeans", chosen))
        return chosen

    def decide(
        self,
        ctx: MethodContext,
        objective: NormalsObjective | RelightObjective,
        chosen: NDArray[np.intp],
    ) -> NDArray[np.intp]:
        _score_start(ctx, objective)
        ctx.report.expected["kmeans"] = objective.cost(chosen)
        return chosen


@dataclass(frozen=True)
class OptimalMethod:
    """Least expected error for the objective: exchange search from the homogeneous layouts."""

    name: str = "optimal"
    summary: str = "least expected error for the objective"
    surface: SurfaceNeed = "flat"
    needs_preview_reason: str = ""
    optimises_objective: bool = True

    def prepare(self, ctx: MethodContext) -> NDArray[np.intp]:
        return ctx.starts[0][1]

    def decide(
        self,
        ctx: MethodContext,
        objective: NormalsObjective | RelightObjective,
        chosen: NDArray[np.intp],
    ) -> NDArray[np.intp]:
        report, n = ctx.report, ctx.n
        if n <= MIN_LIGHTS_FOR_EXCHANGE - 1:
            # With as many lights as unknowns, one shadowed or clipped light leaves a pixel
            # unsolvable: a cliff the expected-error objective cannot see. On the simulated
            # scenes, exchanges at N = 3 collapsed on the tilted one (43° against 1.2°), and
            # choosing among elevation floors by the objective picked near-coplanar high
            # lights (painting 14.6° against 3.7°). So three lights stay homogeneous at the
            # user's floor: the preview-free choice, never worse than itself.
            label, chosen = ctx.starts[0]
            report.start_layout, report.swaps = label, 0
            report.expected[label] = objective.cost(chosen)
            report.kept_layout_why = f"{n} lights leave no redundancy for a shadow or a highlight"
            report.notes.append(
                f"{report.kept_layout_why}: the homogeneous layout ({label}) is kept"
            )
            return chosen
        search = binned_objective(objective)
        res = exchange_search(objective, ctx.starts, search=search, guard=_guard(ctx))
        report.start_layout, report.swaps = res.start_label, res.swaps
        report.guarded_tilt_deg = res.guarded_tilt_deg
        if search is not objective:
            assert isinstance(search, NormalsObjective) and isinstance(objective, NormalsObjective)
            report.search_pixels = (len(objective.n), len(search.n))
        report.expected.update(res.start_costs)
        report.expected["optimal"] = res.cost
        if n >= MANY_LIGHTS and ctx.objective == "normals" and res.swaps > 0:
            report.notes.append(_even_layout_note(ctx, n))
        return res.chosen


def _guard(ctx: MethodContext) -> TiltGuard | None:
    """The tilt guard of the exchange (:mod:`rti_rig.planner.tilt_guard`) around the plane the
    surface estimate sees (the mean of its normals: level for a flat or unreadable preview)."""
    if not tilt_guard_module.ENABLED:
        return None
    up = object_plane(None if ctx.surface is None else ctx.surface.normals)
    return tilt_guard(ctx.candidates.directions, up, [s for _, s in ctx.starts])


#: From this many lights the even layout did better than the optimal plan on brushed steel in
#: the simulator's tests (losses at 20 and 30, docs/research/planner.md)
BRUSHED_LOSS_LIGHTS = 20


def _even_layout_note(ctx: MethodContext, n: int) -> str:
    """The note that an even layout did better in the tests, offering only what the user did
    not choose: the 10° floor where no ``--min-elevation-deg`` was typed, ``--material glossy``
    where another material was, and the even layout as a whole command (``ctx.uniform_said``)
    where the caller gave one. What did better, on brushed metal, is said only from the count
    at which it was seen (:data:`BRUSHED_LOSS_LIGHTS`).

    Why: "--method uniform --min-elevation-deg 10 did better" was said to a user who had set
    ``--min-elevation-deg 55``, as options to splice into a command rather than one to paste;
    and "for brushed metal at 20 lights or more" was said of a plan of 12."""
    layout = "an even layout" if ctx.min_elevation_given else "an even layout from a 10° floor"
    said = f" ({ctx.uniform_said})" if ctx.uniform_said else ""
    glossy = "" if ctx.material == "glossy" else "; for gilding, --material glossy helped"
    if n < BRUSHED_LOSS_LIGHTS:
        return (
            f"from {MANY_LIGHTS} lights the planner gained little over an even layout in "
            f"the tests (docs/research/planner.md): {layout} is worth comparing{said}{glossy}"
        )
    return (
        f"from {MANY_LIGHTS} lights the planner gained little over an even layout in "
        f"the tests (docs/research/planner.md): for brushed metal at {BRUSHED_LOSS_LIGHTS} "
        f"lights or more, {layout} did better{said}{glossy}"
    )


UNIFORM = register_method(UniformMethod())
KMEANS = register_method(KMeansMethod())
OPTIMAL = register_method(OptimalMethod())
