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
   arm's move-time order, :func:`rti_rig.planner.arm_order.order_for_arm` — else nearest neighbour
   from the park pose).

The evidence behind a plan is a :class:`rti_rig.planner.plan_report.PlanReport`. The default
objective is ``normals``: see docs/research/planner.md for the real-dome evidence behind it.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import threadpool_limits

from rti_rig.core.errors import ScheduleError
from rti_rig.core.fit_minimums import NORMAL_MIN_LIGHTS
from rti_rig.core.geometry import az_el_from_direction, fibonacci_cap
from rti_rig.core.lp_format import MAX_LIGHTS
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry, in_band
from rti_rig.core.schedule import LightSchedule
from rti_rig.planner.builtin_methods import MANY_LIGHTS, MIN_LIGHTS_FOR_EXCHANGE
from rti_rig.planner.light_origin import LightOrigin
from rti_rig.planner.methods import MethodContext, PlanMethod, get_method
from rti_rig.planner.objectives import (
    GLOSSY_SPECULAR,
    GLOSSY_WIDTH_DEG,
    HELD_OUT,
    OBJECTIVES,
    Candidates,
    candidates_for,
    check_material,
    check_signal_noise,
    make_objective,
)
from rti_rig.planner.plan_report import PlanReport
from rti_rig.planner.surface_estimate import (
    SurfaceEstimate,
    estimate_surface,
    flat_surface,
    relief_trust,
    sample_surface,
    tilt_stats,
)
from rti_rig.planner.tilt_guard import (
    REPORT_MAX_DEG,
    facing_count,
    object_plane,
    tilt_tolerance,
)
from rti_rig.planner.topography import DepthModelSpec
from rti_rig.planner.uniform import (
    arm_band_note,
    arm_below,
    order_nearest_neighbour,
    select_uniform_leds,
)

__all__ = ["MANY_LIGHTS", "PlanRequest", "make_plan", "plan", "plan_with_report"]

#: The objective used when none is asked for (evidence in docs/research/planner.md).
DEFAULT_OBJECTIVE = "normals"

#: Extra elevation floors tried for the homogeneous starting layouts of ``optimal``.
START_FLOORS_DEG = (10.0, 20.0, 30.0, 40.0)

#: Below this many pixels on a side a preview cannot show relief (the report says so).
TINY_PREVIEW_PX = 16

ArmOrder = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.intp]]


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
    above = el[in_band(el, min_elevation_deg)]
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
                leds = select_uniform_leds(
                    geometry, n, f, max_elevation_deg=ceiling, fewest=MIN_PLAN_LIGHTS
                )
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
    arm_stops: NDArray[np.intp] | None,
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
    assert arm_stops is not None
    return LightSchedule.from_directions(dirs[arm_stops], method=method, provenance=provenance)


def _arm_stops(
    geometry: DomeGeometry | ArmGeometry,
    candidates: Candidates,
    chosen: NDArray[np.intp],
    arm_order: ArmOrder | None,
) -> NDArray[np.intp] | None:
    """The order an arm visits the chosen lights in (``arm_order``, else nearest neighbour
    from the park pose); None on a dome (its schedule is in LED order)."""
    if isinstance(geometry, DomeGeometry):
        return None
    orderer = arm_order or order_nearest_neighbour
    dirs = candidates.directions[chosen]
    return np.asarray(orderer(dirs, geometry.park_direction), dtype=np.intp)


@dataclass(frozen=True)
class PlanRequest:
    """Everything one plan depends on; :meth:`check` is the one place its values are checked.

    ``preview`` is an image (H, W) or (H, W, 3): uint8 is sRGB, uint16 and float are linear
    (see :mod:`rti_rig.planner.topography`); it may be ``None`` for a method whose
    :attr:`~rti_rig.planner.methods.PlanMethod.surface` is not ``"preview"``.

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

    ``arm_order`` orders an arm's lights (the composition root passes the arm's move-time
    order, :func:`rti_rig.planner.arm_order.order_for_arm`); without it, nearest neighbour from
    the park pose.
    """

    preview: NDArray | None
    geometry: DomeGeometry | ArmGeometry
    n: int
    method: str = "optimal"
    objective: str = DEFAULT_OBJECTIVE
    preview_light: tuple[float, float] | None = None
    depth_model: Path | None = None
    min_elevation_deg: float = 0.0
    signal_noise: float = 0.0
    material: str = "auto"
    max_elevation_deg: float = 90.0
    depth_spec: DepthModelSpec | None = None
    arm_order: ArmOrder | None = None
    seed: int = 0
    #: where ``preview_light`` came from: typed (given) or read from a record of the shot
    preview_light_origin: LightOrigin = LightOrigin.GIVEN
    #: each bound of the elevation band was typed (``--min/--max-elevation-deg``), not the
    #: command's default: an arm that cannot reach it all says so even of 0..90, naming only
    #: the options typed
    min_elevation_given: bool = False
    max_elevation_given: bool = False
    #: the rig config and a free folder as shell words, for the ``rti-rig preview`` command a
    #: note offers (the caller knows them; the planner does not): ``RIG --out P`` pasted as
    #: printed had been refused as no rig file, or made a folder named P
    rig_said: str = "RIG.toml"
    preview_folder_said: str = "preview"
    #: the ``rti-rig plan`` command for an even layout of this rig (the caller's words, as
    #: ``rig_said``), for the note that offers one
    uniform_said: str = ""

    def check(self) -> PlanMethod:
        """Refuse what cannot be planned, before any work; returns the method to plan with."""
        return check_plan_options(
            method=self.method,
            objective=self.objective,
            n=self.n,
            has_preview=self.preview is not None,
            preview_light=self.preview_light,
            depth_model=self.depth_model,
            min_elevation_deg=self.min_elevation_deg,
            max_elevation_deg=self.max_elevation_deg,
            signal_noise=self.signal_noise,
            material=self.material,
        )


#: Fewer lights than this determine no surface normal: ``plan`` refuses them by name
#: (``run --lights N`` may still shoot fewer, e.g. to try a rig out). The same figure as the
#: fit's normal map (``core.fit_minimums``), on purpose: below it no plan beats another.
MIN_PLAN_LIGHTS = NORMAL_MIN_LIGHTS


def check_plan_options(
    *,
    method: str,
    objective: str,
    n: int,
    has_preview: bool,
    preview_light: tuple[float, float] | None = None,
    depth_model: Path | None = None,
    min_elevation_deg: float = 0.0,
    max_elevation_deg: float = 90.0,
    signal_noise: float = 0.0,
    material: str = "auto",
    rig: str = "RIG.toml",
    out: str = "DIR",
) -> PlanMethod:
    """The one definition of what a plan may ask; returns the method to plan with (``rig``: the
    rig config as given, and ``out`` a folder for a run, shell words for the commands a
    refusal offers).

    Refused, naming the command-line option: an unknown method, objective or material; a signal
    noise the objective does not model; a method that needs a preview without one; a preview's
    light or depth model without a preview; a depth model that is a folder or no file; an empty
    elevation band; a light count outside 3..1000 (fewer determine no normal; 1000 is the most
    an .lp file may list). Callers check early (before reading any image) with ``has_preview``;
    :func:`plan` checks its request again.
    """
    chosen = get_method(method, rig, out, n)
    if objective not in OBJECTIVES:
        known = ", ".join(OBJECTIVES)
        raise ScheduleError(f"--objective {objective!r} is not known; choose {known}")
    check_signal_noise(signal_noise, objective)
    check_material(material)
    if not has_preview and chosen.surface == "preview":
        raise ScheduleError(chosen.needs_preview_reason)
    if not has_preview and (preview_light is not None or depth_model is not None):
        given = "--preview-light" if preview_light is not None else "--depth-model"
        raise ScheduleError(
            f"{given} describes a preview shot, but no preview was given: give the preview, "
            f"or drop {given}"
        )
    if depth_model is not None and Path(depth_model).is_dir():
        # "file not found" of a folder that is there read as a typo in its name
        raise ScheduleError(
            f"--depth-model {depth_model} is a folder: give the model file in it (.onnx)"
        )
    if depth_model is not None and not Path(depth_model).is_file():
        raise ScheduleError(f"--depth-model {depth_model}: file not found")
    check_elevation_band(min_elevation_deg, max_elevation_deg)
    if n < MIN_PLAN_LIGHTS:
        raise ScheduleError(
            f"--lights {n}: give at least {MIN_PLAN_LIGHTS} lights to plan; fewer cannot "
            "determine a surface normal, so no planner can do better than another (a 2-light "
            "plan read 90° expected error)"
        )
    if n > MAX_LIGHTS:
        raise ScheduleError(
            f"--lights {n}: at most {MAX_LIGHTS} lights (the most an .lp file may list "
            "for readers such as relight)"
        )
    return chosen


def plan(request: PlanRequest) -> tuple[LightSchedule, PlanReport]:
    """The schedule for ``request`` and the evidence behind it.

    Dome steps carry LED indices and the dome's LED names as labels, in ascending LED order; arm
    steps are ordered for short moves. The evidence is also in
    ``schedule.provenance["report"]``.

    BLAS is held to one thread while planning: every matrix here is small (3 to 16 columns),
    and a threaded BLAS on a busy machine made such products 40× slower, not faster.
    """
    method = request.check()
    dome = request.geometry if isinstance(request.geometry, DomeGeometry) else None
    if (dome is not None and request.n < dome.count) or method.name == "kmeans":
        # a dome's homogeneous layouts of fewer lights than LEDs and k-means' targets are
        # matched to the rig's lights by scipy's assignment solver, imported on first use (0.3
        # s; an arm's plan, or one of every LED, never loads it): loaded here so that the
        # report's "planned in" times the planning, not an import
        import scipy.optimize  # noqa: F401
    if method.name == "kmeans":
        # k-means clusters with scikit-learn, whose first import (sklearn.cluster, ~5 s on a busy
        # machine) dwarfs the planning: loaded here for the same reason, and only for k-means
        import sklearn.cluster  # noqa: F401
    with threadpool_limits(limits=1):
        return _plan(request, method)


def plan_with_report(*args: Any, **kwargs: Any) -> tuple[LightSchedule, PlanReport]:
    """:func:`plan` with the fields of :class:`PlanRequest` as arguments, in its order
    (``preview, geometry, n, method, objective, preview_light, depth_model, …``) or by name."""
    return plan(PlanRequest(*args, **kwargs))


def make_plan(*args: Any, **kwargs: Any) -> LightSchedule:
    """An ordered schedule (:func:`plan_with_report` without the report; it stays in
    ``schedule.provenance["report"]``)."""
    return plan_with_report(*args, **kwargs)[0]


def _plan(req: PlanRequest, method: PlanMethod) -> tuple[LightSchedule, PlanReport]:
    t0 = time.perf_counter()
    geometry, n = req.geometry, req.n
    relit_band, cut = _relit_band(geometry, req.min_elevation_deg, req.max_elevation_deg)
    band_note = None
    if isinstance(geometry, ArmGeometry):
        band_note = arm_band_note(
            geometry,
            req.min_elevation_deg,
            req.max_elevation_deg,
            min_given=req.min_elevation_given,
            max_given=req.max_elevation_given,
        )
        geometry = arm_below(geometry, req.max_elevation_deg)
    candidates, starts = _candidates_and_starts(
        geometry, n, req.min_elevation_deg, req.max_elevation_deg
    )
    rig = f"a dome of {geometry.count} LEDs" if isinstance(geometry, DomeGeometry) else "an arm"
    report = PlanReport(
        method.name,
        req.objective,
        n,
        rig,
        len(candidates),
        req.min_elevation_deg,
        req.max_elevation_deg if cut else 90.0,  # a ceiling above every light changes nothing
        material=req.material,
    )
    if band_note is not None:
        report.notes.append(band_note)
    prov: dict[str, Any] = {
        "n": n,
        "min_elevation_deg": req.min_elevation_deg,
        "max_elevation_deg": req.max_elevation_deg,
        "objective": req.objective,
    }

    surface = _surface_for(req, method, report)
    ctx = MethodContext(
        n,
        candidates,
        starts,
        surface,
        report,
        req.seed,
        req.material,
        req.objective,
        req.max_elevation_deg,
        cut,
        req.min_elevation_given,
        req.uniform_said,
    )
    chosen = method.prepare(ctx)
    if surface is not None:
        held_out = _held_out_lights(candidates, relit_band, cut)
        sample = sample_surface(surface, candidates, held_out, seed=req.seed, material=req.material)
        obj = make_objective(req.objective, sample, candidates, n, starts[0][1], req.signal_noise)
        report.signal_noise = req.signal_noise
        _note_assumptions(report, method, req)
        report.model = getattr(obj, "model", "lambert (photometric stereo)")
        report.expected_meaning = (
            "expected RMS normal error (degrees)"
            if req.objective == "normals"
            else f"expected relighting MSE per unit albedo ({report.model})"
        )
        chosen = method.decide(ctx, obj, chosen)
        report.notes.append(_expected_caveat(report.shading_explained_r2, req.material))
    up = object_plane(None if surface is None else surface.normals)
    report.tilt_tolerance_deg = tilt_tolerance(candidates.directions[chosen], up, REPORT_MAX_DEG)
    report.level_facing_lights = facing_count(candidates.directions[chosen], up)
    report.even_tilt_tolerance_deg = tilt_tolerance(
        candidates.directions[starts[0][1]], up, REPORT_MAX_DEG
    )
    if surface is None and req.material != "auto":
        report.notes.append(
            f"--material {req.material} is not used: no surface was modelled "
            f"({method.name} needs none)"
        )
    report.seconds = time.perf_counter() - t0
    # the arm's stop order is part of planning (seconds at 1000 stops): timed apart and said,
    # where "planned in 0.01 s" had left it out
    t1 = time.perf_counter()
    stops = _arm_stops(geometry, candidates, chosen, req.arm_order)
    if stops is not None:
        report.order_seconds = time.perf_counter() - t1
    prov["report"] = report.to_dict()
    schedule = _schedule(geometry, candidates, chosen, method.name, prov, stops)
    return schedule, report


#: Below this R² the preview's shading says little of the relief (the shape-from-shading fit
#: of the real icon read about 0.1; the replayed 18-light dome 0.08).
POOR_SHADING_R2 = 0.3


def _expected_caveat(r2: float | None, material: str = "auto") -> str:
    """What the expected errors are: the camera noise propagated on the modelled surface. A
    session measures more (gloss, shadows, interreflection, relief the preview did not show):
    on the replayed 18-light dome a 9-light plan "expected" 1.2° and measured 4.7° mean.

    A declared glossy surface's gloss is modelled (the declared lobe): "not gloss" had been
    said beside "declared glossy: highlights modelled as a 30° lobe", which read as a
    contradiction; what is not counted there is the object's own gloss beyond that lobe."""
    unseen = (
        "not the object's own gloss beyond the declared lobe, nor shadows or relief"
        if material == "glossy"
        else "not gloss, shadows or relief"
    )
    text = (
        f"the expected errors count the camera noise on the modelled surface only, {unseen} "
        "the preview cannot show: read them to compare layouts, as a lower bound of what a "
        "session measures"
    )
    if r2 is not None and r2 < POOR_SHADING_R2:
        text += (
            f"; here the preview's shading fits the relief poorly (R²={r2:.2f}), so the relief "
            "was flattened towards a level surface and says little of this object"
        )
    return text


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
    if isinstance(geometry, ArmGeometry):
        # an arm's starts are indexed by position among the extra directions candidates_for
        # keeps first, so a start it would filter out (unreachable by rounding) is left out
        # here, before it can shift the indices of the starts after it
        kept = [u for u in uniforms if geometry.reachable(u[1]).all()]
        if not kept or kept[0] is not uniforms[0]:
            raise ScheduleError(
                f"the homogeneous layout ≥{min_elevation_deg:g}° is not reachable by this arm"
            )
        uniforms = kept
    extra = np.concatenate([u[1] for u in uniforms]) if isinstance(geometry, ArmGeometry) else None
    candidates = candidates_for(geometry, min_elevation_deg, extra, max_elevation_deg)
    starts: list[tuple[str, NDArray[np.intp]]] = []
    offset = 0
    for u in uniforms:
        starts.append((u[0], _to_candidate_indices(u, candidates, offset)))
        offset += len(u[1])
    return candidates, starts


def _surface_for(
    req: PlanRequest, method: PlanMethod, report: PlanReport
) -> SurfaceEstimate | None:
    """The surface to plan for: estimated from the preview, assumed level without one (for a
    method that plans for a ``flat`` surface), or None when the method needs none; its facts go
    into ``report``."""
    preview, material = req.preview, req.material
    surface: SurfaceEstimate | None = None
    if preview is None and method.surface == "flat":
        surface = flat_surface()
        kind = "glossy" if material == "glossy" else "matte"
        report.notes.append(
            f"no preview: planned for a level, {kind} surface (the model alone; on the "
            "benchmarks in docs/research/planner.md this did as well as planning from a preview)"
        )
    elif preview is not None:
        try:
            surface = estimate_surface(
                preview,
                req.preview_light,
                req.depth_model,
                req.depth_spec,
                light_origin=req.preview_light_origin,
            )
        except ScheduleError as exc:
            if method.surface != "none":
                raise
            # a method that needs no surface does not need the preview: report, do not fail
            report.notes.append(f"preview not evaluated: {exc}")
    if surface is not None:
        report.relief_source = surface.relief_source
        report.rms_tilt_deg, report.p90_tilt_deg = tilt_stats(surface.normals)
    if surface is not None and preview is not None:
        _report_preview_facts(preview, surface, report)
        if surface.light_origin.known:  # recorded or --preview-light: a known light
            _note_preview_outside_band(surface, req, report)
    return surface


def _note_preview_outside_band(
    surface: SurfaceEstimate, req: PlanRequest, report: PlanReport
) -> None:
    """One line when the preview's known light lies outside the plan's band: a notice, not a
    refusal (the plan still keeps to the band; the preview is evidence of the surface), but a
    user who set a 45° ceiling for a gilded object should know the preview was shot at 50°,
    and how to shoot one within the band. An estimated light is not known well enough to say
    so (docs/research/planner.md: 17–59° off on the real icon)."""
    _, el = az_el_from_direction(surface.light)
    el = float(el)
    lo, hi = req.min_elevation_deg, req.max_elevation_deg
    if lo - 0.05 <= el <= hi + 0.05:  # the rounding of a recorded or typed light
        return
    flag = f"--max-elevation-deg {hi:g}" if el > hi else f"--min-elevation-deg {lo:g}"
    side = "above" if el > hi else "below"
    report.notes.append(
        f"the preview's light is at {el:.1f}° elevation, {side} this plan's {flag}: the "
        f"preview was shot under a light the plan keeps out (`rti-rig preview {req.rig_said} "
        f"--out {req.preview_folder_said} {flag}` shoots one within the band)"
    )


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
    report.preview_light_origin = surface.light_origin
    report.preview_light_why_zenith = surface.light_why_zenith
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


def _note_assumptions(report: PlanReport, method: PlanMethod, req: PlanRequest) -> None:
    """Notes on the declared signal noise and material and on the objective's evidence."""
    n, material = req.n, req.material
    chooses_by_objective = method.optimises_objective and n >= MIN_LIGHTS_FOR_EXCHANGE
    if req.signal_noise > 0 and not chooses_by_objective:
        report.notes.append(
            f"--signal-noise changes only the expected errors reported here, not the "
            f"lights {method.name} chooses"
        )
    if material != "auto":
        unused = (
            ""
            if chooses_by_objective
            else f" (it changes only the expected errors reported here, not the lights "
            f"{method.name} chooses)"
        )
        what = (
            f"highlights modelled as a {GLOSSY_WIDTH_DEG:g}° lobe of strength "
            f"{GLOSSY_SPECULAR:g} around the mirror direction"
            if material == "glossy"
            else "no highlight modelled"
        )
        report.notes.append(f"declared {material}: {what}, whatever the preview shows{unused}")
    if req.objective == "relight" and method.optimises_objective:
        report.notes.append(
            "evidence: on the real dome of docs/research/planner.md the normals objective's "
            "layouts relit better than this objective's at 6, 9, 12 and 18 lights (mean PSNR over "
            "144 draws; median over 8 previews with --material glossy too); for "
            "relighting, --objective normals is the tested choice"
        )
