"""One entry point from a preview shot to an ordered light schedule: :func:`make_plan`.

Pipeline (each step a pure function in its own module):

1. the surface (:mod:`rti_rig.planner.surface_estimate`): the preview reduced to a planning image,
   its light (given or estimated), a relief (an ONNX depth model or shape from shading) scaled by
   the preview's shading, and normals — or, with no preview at all, a level, matte surface
   (:func:`rti_rig.planner.surface_estimate.flat_surface`; on the benchmarks it planned as well);
2. the method: ``uniform`` (homogeneous, no preview needed), ``kmeans`` (the paper's) or
   ``optimal`` (exchange search on an objective, :mod:`rti_rig.planner.optimal`);
3. the rig's constraints (usable LEDs without repeats / reachable arm band) and its order
   (ascending LED index on a dome; on an arm the ``arm_order`` passed in — the CLI passes the
   servos' move-time order, :func:`rti_rig.planner.arm_order.order_for_arm` — else nearest neighbour
   from the park pose).

The evidence behind a plan is a :class:`rti_rig.planner.plan_report.PlanReport`. The default
objective is ``normals``: see docs/research/planner.md for the real-dome evidence behind it.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from rti_rig.planner.kmeans_method import plan_kmeans
from rti_rig.planner.objectives import (
    GLOSSY_SPECULAR,
    GLOSSY_WIDTH_DEG,
    HELD_OUT,
    OBJECTIVES,
    Candidates,
    NormalsObjective,
    RelightObjective,
    candidates_for,
    check_material,
    check_signal_noise,
    make_objective,
)
from rti_rig.planner.optimal import exchange_search
from rti_rig.planner.plan_report import PlanReport
from rti_rig.planner.surface_estimate import (
    SurfaceEstimate,
    estimate_surface,
    flat_surface,
    relief_trust,
    sample_surface,
    tilt_stats,
)
from rti_rig.planner.topography import DepthModelSpec
from rti_rig.planner.uniform import arm_below, order_nearest_neighbour, select_uniform_leds
from threadpoolctl import threadpool_limits

from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import az_el_from_direction, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.core.schedule import LightSchedule

METHODS: tuple[str, ...] = ("uniform", "kmeans", "optimal")

#: The objective used when none is asked for (evidence in docs/research/planner.md).
DEFAULT_OBJECTIVE = "normals"

#: Extra elevation floors tried for the homogeneous starting layouts of ``optimal``.
START_FLOORS_DEG = (10.0, 20.0, 30.0, 40.0)

#: Below this many pixels on a side a preview cannot show relief (the report says so).
TINY_PREVIEW_PX = 16

ArmOrder = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.intp]]

#: Below this many lights the exchange search is not run (see ``_run_method``): 3 lights are exactly
#: the unknowns of the Lambertian fit, with no redundancy left for a shadow or a highlight.
MIN_LIGHTS_FOR_EXCHANGE = 4

#: From this light count up the benchmarks found the ``optimal`` normals plan's gain over a
#: homogeneous layout small and object-dependent (real dome: a tie at 12 lights and −0.39° at 18
#: by default, wins at both declared glossy; simulator: losses on brushed steel at 20 and 30
#: against a 10° floor), so the report says so.
MANY_LIGHTS = 12


def check_elevation_band(min_elevation_deg: float, max_elevation_deg: float) -> None:
    """Refuse an elevation band that is empty or leaves the hemisphere."""
    if not 0.0 <= min_elevation_deg < 90.0:
        raise ScheduleError(
            f"--min-elevation-deg {min_elevation_deg:g}: give an elevation in [0, 90) degrees"
        )
    if not min_elevation_deg < max_elevation_deg <= 90.0:
        raise ScheduleError(
            f"--max-elevation-deg {max_elevation_deg:g}: give an elevation above the floor "
            f"({min_elevation_deg:g}°) and at most 90°"
        )


def _elevation_range(
    geometry: DomeGeometry | ArmGeometry, min_elevation_deg: float
) -> tuple[float, float]:
    """The lowest and highest elevation the rig offers at or above the floor (degrees)."""
    if isinstance(geometry, ArmGeometry):
        return geometry.elevation_band(min_elevation_deg)
    _, el = az_el_from_direction(geometry.directions)
    above = el[el >= min_elevation_deg - 1e-9]
    if len(above) == 0:
        raise ScheduleError(
            f"the dome has no LED at or above {min_elevation_deg:g}° elevation; lower "
            "--min-elevation-deg"
        )
    return float(above.min()), float(above.max())


def _uniform_layouts(
    geometry: DomeGeometry | ArmGeometry, n: int, floors: list[float], ceiling: float = 90.0
) -> tuple[list[tuple[str, NDArray[np.float64], NDArray[np.intp] | None]], str | None]:
    """Homogeneous layouts (label, directions, dome LEDs) for each feasible floor, below
    ``ceiling`` (an arm is limited by :func:`arm_below` beforehand)."""
    out: list[tuple[str, NDArray[np.float64], NDArray[np.intp] | None]] = []
    first_error: str | None = None
    for f in floors:
        try:
            if isinstance(geometry, DomeGeometry):
                leds = select_uniform_leds(geometry, n, f, max_elevation_deg=ceiling)
                out.append((f"uniform ≥{f:g}°", geometry.directions[leds], leds))
            else:
                out.append((f"uniform ≥{f:g}°", geometry.homogeneous(n, f), None))
        except ScheduleError as exc:
            first_error = first_error or str(exc)
    return out, first_error


def _to_candidate_indices(
    layout: tuple[str, NDArray[np.float64], NDArray[np.intp] | None],
    candidates: Candidates,
    offset: int,
) -> NDArray[np.intp]:
    _, dirs, leds = layout
    if leds is not None and candidates.leds is not None:
        where = {int(led): i for i, led in enumerate(candidates.leds)}
        return np.array([where[int(i)] for i in leds], dtype=np.intp)
    return np.arange(offset, offset + len(dirs), dtype=np.intp)


def _schedule(
    geometry: DomeGeometry | ArmGeometry,
    candidates: Candidates,
    chosen: NDArray[np.intp],
    method: str,
    provenance: dict[str, Any],
    arm_order: ArmOrder | None,
) -> LightSchedule:
    dirs = candidates.directions[chosen]
    if isinstance(geometry, DomeGeometry):
        assert candidates.leds is not None
        leds = candidates.leds[chosen]
        order = np.argsort(leds, kind="stable")
        return LightSchedule.from_directions(
            dirs[order],
            leds=[int(i) for i in leds[order]],
            labels=[geometry.names[int(i)] for i in leds[order]],
            method=method,
            provenance=provenance,
        )
    orderer = arm_order or order_nearest_neighbour
    order = np.asarray(orderer(dirs, geometry.park_direction), dtype=np.intp)
    return LightSchedule.from_directions(dirs[order], method=method, provenance=provenance)


def plan_with_report(
    preview: NDArray | None,
    geometry: DomeGeometry | ArmGeometry,
    n: int,
    method: str = "optimal",
    objective: str = DEFAULT_OBJECTIVE,
    preview_light: tuple[float, float] | None = None,
    depth_model: Path | None = None,
    min_elevation_deg: float = 0.0,
    *,
    depth_spec: DepthModelSpec | None = None,
    arm_order: ArmOrder | None = None,
    seed: int = 0,
    signal_noise: float = 0.0,
    material: str = "auto",
    max_elevation_deg: float = 90.0,
) -> tuple[LightSchedule, PlanReport]:
    """The schedule and the evidence behind it; see :func:`make_plan`.

    ``max_elevation_deg``: no light above this elevation (90 = none excluded): lights near
    the camera axis put mirror highlights on a level glossy object (docs/research/planner.md, "An
    elevation ceiling").

    ``material``: what the user knows of the surface (:data:`rti_rig.planner.objectives.MATERIALS`):
    ``auto`` (default) reads highlights from the preview, ``matte`` models none, ``glossy``
    (polished metal, gilding, varnish) models a strong, broad highlight lobe even when the
    preview does not show one — on a flat glossy object it never does (docs/research/planner.md).

    ``signal_noise``: image noise proportional to the signal, relative to it (0.05 = 5 %), for
    the ``normals`` objective — an uncalibrated dome's LED spread and 8-bit JPEG captures
    (:data:`rti_rig.planner.objectives.SIGNAL_NOISE_JPEG_DOME`); 0 models additive noise only.

    BLAS is held to one thread while planning: every matrix here is small (3 to 16 columns),
    and a threaded BLAS on a busy machine made such products 40× slower, not faster.
    """
    with threadpool_limits(limits=1):
        return _plan(
            preview,
            geometry,
            n,
            method,
            objective,
            preview_light,
            depth_model,
            min_elevation_deg,
            depth_spec,
            arm_order,
            seed,
            signal_noise,
            material,
            max_elevation_deg,
        )


def _plan(
    preview: NDArray | None,
    geometry: DomeGeometry | ArmGeometry,
    n: int,
    method: str,
    objective: str,
    preview_light: tuple[float, float] | None,
    depth_model: Path | None,
    min_elevation_deg: float,
    depth_spec: DepthModelSpec | None,
    arm_order: ArmOrder | None,
    seed: int,
    signal_noise: float = 0.0,
    material: str = "auto",
    max_elevation_deg: float = 90.0,
) -> tuple[LightSchedule, PlanReport]:
    t0 = time.perf_counter()
    _check_request(
        n, method, objective, signal_noise, material, min_elevation_deg, max_elevation_deg
    )
    relit_band, cut = _relit_band(geometry, min_elevation_deg, max_elevation_deg)
    if isinstance(geometry, ArmGeometry):
        geometry = arm_below(geometry, max_elevation_deg)
    candidates, starts = _candidates_and_starts(geometry, n, min_elevation_deg, max_elevation_deg)
    rig = f"a dome of {geometry.count} LEDs" if isinstance(geometry, DomeGeometry) else "an arm"
    report = PlanReport(
        method,
        objective,
        n,
        rig,
        len(candidates),
        min_elevation_deg,
        max_elevation_deg if cut else 90.0,  # a ceiling above every light changes nothing
        material=material,
    )
    prov: dict[str, Any] = {
        "n": n,
        "min_elevation_deg": min_elevation_deg,
        "max_elevation_deg": max_elevation_deg,
        "objective": objective,
    }

    chosen = starts[0][1]
    surface = _surface_for(
        preview, method, material, preview_light, depth_model, depth_spec, report
    )
    if surface is not None:
        held_out = _held_out_lights(candidates, relit_band, cut)
        sample = sample_surface(surface, candidates, held_out, seed=seed, material=material)
        if method == "kmeans":
            chosen = _run_kmeans(surface, n, candidates, seed, cut, max_elevation_deg, report)
            starts.append(("kmeans", chosen))
        obj = make_objective(objective, sample, candidates, n, starts[0][1], signal_noise)
        report.signal_noise = signal_noise
        _note_assumptions(report, method, objective, n, signal_noise, material)
        chosen = _run_method(obj, method, objective, n, material, starts, chosen, report)
    if surface is None and material != "auto":
        report.notes.append(
            f"--material {material} is not used: no surface was modelled ({method} needs none)"
        )
    report.seconds = time.perf_counter() - t0
    prov["report"] = report.to_dict()
    schedule = _schedule(geometry, candidates, chosen, method, prov, arm_order)
    return schedule, report


def _check_request(
    n: int,
    method: str,
    objective: str,
    signal_noise: float,
    material: str,
    min_elevation_deg: float,
    max_elevation_deg: float,
) -> None:
    """Refuse an unknown method, objective or material, a light count below 1, a signal noise
    the objective does not model and an empty elevation band."""
    if method not in METHODS:
        raise ScheduleError(f"unknown method '{method}'; use one of {', '.join(METHODS)}")
    if objective not in OBJECTIVES:
        raise ScheduleError(f"unknown objective '{objective}'; use one of {', '.join(OBJECTIVES)}")
    if n < 1:
        raise ScheduleError(f"--lights must be at least 1, got {n}")
    check_signal_noise(signal_noise, objective)
    check_material(material)
    check_elevation_band(min_elevation_deg, max_elevation_deg)


def _relit_band(
    geometry: DomeGeometry | ArmGeometry, min_elevation_deg: float, max_elevation_deg: float
) -> tuple[tuple[float, float], bool]:
    """The elevations (degrees) the relight objective scores, and whether the ceiling cuts the
    rig's range above the floor."""
    # the relight objective scores relighting over the rig's whole range above the floor, the
    # directions above a ceiling included (a user relights there too), so take it before the cut
    relit_band, cut = (0.0, 90.0), False
    if max_elevation_deg < 90.0:
        try:
            relit_band = _elevation_range(geometry, min_elevation_deg)
            cut = relit_band[1] > max_elevation_deg
        except ScheduleError:
            pass  # nothing above the floor: the homogeneous layouts below say so
    return relit_band, cut


def _candidates_and_starts(
    geometry: DomeGeometry | ArmGeometry, n: int, min_elevation_deg: float, max_elevation_deg: float
) -> tuple[Candidates, list[tuple[str, NDArray[np.intp]]]]:
    """The usable light positions and the homogeneous starting layouts (label, candidate
    indices), the one at the user's floor first (an arm is limited by :func:`arm_below`
    beforehand)."""
    floors = [min_elevation_deg] + [
        f for f in START_FLOORS_DEG if min_elevation_deg < f < max_elevation_deg
    ]
    uniforms, uniform_error = _uniform_layouts(geometry, n, floors, max_elevation_deg)
    if not uniforms or uniforms[0][0] != f"uniform ≥{min_elevation_deg:g}°":
        # the user's own floor must work; the extra floors are optional starting points
        raise ScheduleError(uniform_error or "no homogeneous layout fits this rig")
    extra = np.concatenate([u[1] for u in uniforms]) if isinstance(geometry, ArmGeometry) else None
    candidates = candidates_for(geometry, min_elevation_deg, extra, max_elevation_deg)
    starts: list[tuple[str, NDArray[np.intp]]] = []
    offset = 0
    for u in uniforms:
        starts.append((u[0], _to_candidate_indices(u, candidates, offset)))
        offset += len(u[1])
    return candidates, starts


def _surface_for(
    preview: NDArray | None,
    method: str,
    material: str,
    preview_light: tuple[float, float] | None,
    depth_model: Path | None,
    depth_spec: DepthModelSpec | None,
    report: PlanReport,
) -> SurfaceEstimate | None:
    """The surface to plan for: estimated from the preview, assumed level without one (for
    ``optimal``), or None when the method needs none; its facts go into ``report``."""
    if method == "kmeans" and preview is None:
        raise ScheduleError(
            "--method kmeans clusters the preview's normals; give a preview shot, or use "
            "--method optimal (which plans for a flat surface without one) or uniform"
        )
    surface: SurfaceEstimate | None = None
    if preview is None and (preview_light is not None or depth_model is not None):
        given = "--preview-light" if preview_light is not None else "--depth-model"
        raise ScheduleError(
            f"{given} describes a preview shot, but no preview was given: give the preview, "
            f"or drop {given}"
        )
    if preview is None and method == "optimal":
        surface = flat_surface()
        kind = "glossy" if material == "glossy" else "matte"
        report.notes.append(
            f"no preview: planned for a level, {kind} surface (the model alone; on the "
            "benchmarks in docs/research/planner.md this did as well as planning from a preview)"
        )
    elif preview is not None:
        try:
            surface = estimate_surface(preview, preview_light, depth_model, depth_spec)
        except ScheduleError as exc:
            if method != "uniform":
                raise
            # the homogeneous layout does not need the preview: report, do not fail
            report.notes.append(f"preview not evaluated: {exc}")
    if surface is not None:
        report.relief_source = surface.relief_source
        report.rms_tilt_deg, report.p90_tilt_deg = tilt_stats(surface.normals)
    if surface is not None and preview is not None:
        _report_preview_facts(preview, surface, report)
    return surface


def _report_preview_facts(preview: NDArray, surface: SurfaceEstimate, report: PlanReport) -> None:
    """Facts measured on the preview (none of them exist without one)."""
    az, el = az_el_from_direction(surface.light)
    report.preview_shape = tuple(np.asarray(preview).shape)
    if min(report.preview_shape[:2]) < TINY_PREVIEW_PX:
        report.notes.append(
            f"the preview is only {report.preview_shape[1]}×{report.preview_shape[0]} px: "
            "too small to show relief or the light's direction reliably, so this plan rests "
            "on very little evidence (give a larger preview, or none for the plan of a "
            "level surface)"
        )
    report.preview_light_az_el_deg = (float(az), float(el))
    report.preview_light_source = surface.light_source
    report.planning_shape = tuple(surface.image.shape)
    report.relief_scale = surface.fit.scale * relief_trust(surface.fit)
    report.shading_explained_r2 = surface.fit.explained
    report.highlight_hint = surface.fit.bright_outliers
    report.nonfinite_relief_repaired = surface.nonfinite_repaired
    if surface.nonfinite_repaired:
        report.notes.append(
            f"{surface.nonfinite_repaired} NaN/infinite relief values were replaced by the median"
        )


def _held_out_lights(
    candidates: Candidates, relit_band: tuple[float, float], cut: bool
) -> NDArray[np.float64]:
    """The held-out lights the objectives score a layout on: over the relit band under a
    ceiling that cuts the rig's range, otherwise over the candidates' range."""
    if cut:
        lo, hi = relit_band
    else:  # exactly the candidates' range, as before ceilings existed
        _, cel = az_el_from_direction(candidates.directions)
        lo, hi = float(cel.min()), float(cel.max())
    return fibonacci_cap(HELD_OUT, max(lo, 0.0), hi if hi > lo + 1.0 else 90.0)


def _run_kmeans(
    surface: SurfaceEstimate,
    n: int,
    candidates: Candidates,
    seed: int,
    cut: bool,
    max_elevation_deg: float,
    report: PlanReport,
) -> NDArray[np.intp]:
    """The paper's method: the usable positions nearest the preview's normal clusters."""
    # the paper clusters the depth gradient's normals as they come: no shrinkage
    raw = surface.fitted_normals if surface.fitted_normals is not None else surface.normals
    chosen, km = plan_kmeans(raw, n, candidates, seed)
    report.kmeans_distinct_normals = km.distinct_normals
    if cut:
        report.notes.append(
            f"kmeans puts each light at the usable position nearest its cluster centre: "
            f"under the {max_elevation_deg:g}° ceiling the clusters of a near-level "
            "surface all land on the ceiling's ring"
        )
    if km.distinct_normals < n:
        report.notes.append(
            f"only {km.distinct_normals} distinct normals for {n} clusters: the "
            "remaining lights sit on the usable positions nearest the cluster centres"
        )
    return chosen


def _note_assumptions(
    report: PlanReport,
    method: str,
    objective: str,
    n: int,
    signal_noise: float,
    material: str,
) -> None:
    """Notes on the declared signal noise and material and on the objective's evidence."""
    if signal_noise > 0 and (method != "optimal" or n < MIN_LIGHTS_FOR_EXCHANGE):
        report.notes.append(
            f"--signal-noise changes only the expected errors reported here, not the "
            f"lights {method} chooses"
        )
    if material != "auto":
        unused = (
            ""
            if method == "optimal" and n >= MIN_LIGHTS_FOR_EXCHANGE
            else f" (it changes only the expected errors reported here, not the lights "
            f"{method} chooses)"
        )
        what = (
            f"highlights modelled as a {GLOSSY_WIDTH_DEG:g}° lobe of strength "
            f"{GLOSSY_SPECULAR:g} around the mirror direction"
            if material == "glossy"
            else "no highlight modelled"
        )
        report.notes.append(f"declared {material}: {what}, whatever the preview shows{unused}")
    if objective == "relight" and method == "optimal":
        report.notes.append(
            "evidence: on the real dome of docs/research/planner.md the normals objective's "
            "layouts relit better than this objective's at 6, 9, 12 and 18 lights (mean PSNR over "
            "144 draws; median over 8 previews with --material glossy too); for "
            "relighting, --objective normals is the tested choice"
        )


def _run_method(
    obj: NormalsObjective | RelightObjective,
    method: str,
    objective: str,
    n: int,
    material: str,
    starts: list[tuple[str, NDArray[np.intp]]],
    chosen: NDArray[np.intp],
    report: PlanReport,
) -> NDArray[np.intp]:
    """The lights ``method`` chooses (``chosen`` unless it is ``optimal``), with the expected
    errors of the layouts it compared recorded in ``report``."""
    report.model = getattr(obj, "model", "lambert (photometric stereo)")
    report.expected_meaning = (
        "expected RMS normal error (degrees)"
        if objective == "normals"
        else f"expected relighting MSE per unit albedo ({report.model})"
    )
    if method == "optimal" and n <= MIN_LIGHTS_FOR_EXCHANGE - 1:
        # With as many lights as unknowns, one shadowed or clipped light leaves a pixel
        # unsolvable: a cliff the expected-error objective cannot see. On the simulated
        # scenes, exchanges at N = 3 collapsed on the tilted one (43° against 1.2°), and
        # choosing among elevation floors by the objective picked near-coplanar high
        # lights (painting 14.6° against 3.7°). So three lights stay homogeneous at the
        # user's floor: the preview-free choice, never worse than itself.
        label, chosen = starts[0]
        report.start_layout, report.swaps = label, 0
        report.expected[label] = obj.cost(chosen)
        report.notes.append(
            f"{n} lights leave no redundancy for a shadow or a highlight: the homogeneous "
            f"layout ({label}) is kept"
        )
    elif method == "optimal":
        res = exchange_search(obj, starts)
        chosen = res.chosen
        report.start_layout, report.swaps = res.start_label, res.swaps
        report.expected.update(res.start_costs)
        report.expected["optimal"] = res.cost
        if n >= MANY_LIGHTS and objective == "normals" and res.swaps > 0:
            glossy = "" if material == "glossy" else "; for gilding, --material glossy helped"
            report.notes.append(
                f"from {MANY_LIGHTS} lights the planner gained little over an even layout in "
                "the tests (docs/research/planner.md): for brushed metal at 20 lights or more, "
                f"--method uniform --min-elevation-deg 10 did better{glossy}"
            )
    else:
        report.expected[starts[0][0]] = obj.cost(starts[0][1])
        if method == "kmeans":
            report.expected["kmeans"] = obj.cost(chosen)
    return chosen


def make_plan(
    preview: NDArray | None,
    geometry: DomeGeometry | ArmGeometry,
    n: int,
    method: str = "optimal",
    objective: str = DEFAULT_OBJECTIVE,
    preview_light: tuple[float, float] | None = None,
    depth_model: Path | None = None,
    min_elevation_deg: float = 0.0,
    signal_noise: float = 0.0,
    material: str = "auto",
    max_elevation_deg: float = 90.0,
) -> LightSchedule:
    """An ordered schedule of ``n`` lights for ``geometry`` planned from one preview.

    ``preview`` is an image (H, W) or (H, W, 3): uint8 is sRGB, uint16 and float are linear
    (see :mod:`rti_rig.planner.topography`). It may be ``None`` for ``uniform`` (no preview needed)
    and ``optimal`` (which then plans for a level, matte surface:
    :func:`rti_rig.planner.surface_estimate.flat_surface`). Dome steps carry LED indices and the
    dome's LED names as labels, in ascending LED order; arm steps are ordered for short moves from
    the park pose. The evidence is in ``schedule.provenance["report"]`` (or use
    :func:`plan_with_report`).
    """
    args = (preview, geometry, n, method, objective, preview_light, depth_model, min_elevation_deg)
    return plan_with_report(
        *args, signal_noise=signal_noise, material=material, max_elevation_deg=max_elevation_deg
    )[0]
