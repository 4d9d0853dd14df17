"""What an adaptive session with ``--lights N`` can still reach once its starting lights are shot.

Why: adaptive with N known shoots 4 starting lights (``START_LIGHTS``) before it knows anything,
then chooses among designs that *complete those lights* to the homogeneous layout of N above a
floor (``planner.adaptive.homogeneous_completion``). However good its model of the object, it
can only end with one of those completions. This script measures, on the simulator's scenes
and the same paired draws as ``benchmarks.adaptive`` (24 of 240 lights out), the true normal
error of every floor's completion when the design is decided at the first decision (4 images:
no light of any design shot yet, so no mixture), and the **oracle**: the best floor per draw,
i.e. what a perfect model deciding at once would get. Against the hindsight-tuned homogeneous
layout (the bar of ``benchmarks.adaptive``), an oracle above the bar is a loss no model can
undo: only another start can.

Starts compared (each is 4 lights of the default floor's layout, so the default design stays
exactly that layout):

* ``default``: the 4 closest to a homogeneous layout of 4 (``dome_start``, what ships);
* ``hedge-all``: first the lights that also belong to the most other floors' layouts, then
  closest to a homogeneous layout of 4 (lexicographic);
* ``hedge-20``: the same with the 20° layout only;
* ``shared-3``: 3 lights that both the default and the 20° layouts hold (where they share 3;
  else ``default``): both designs stay exactly reachable, the first decision is on 3 images;
* ``above-floor``: matched only among the default layout's lights at or above
  ``START_FLOOR_DEG`` (what ships for ``--objective relight`` since format 9), and
  ``all-lights``: among all of them (what ships for the normals objective; up to format 8 for
  both) — whatever the objective.

``--measure relight`` scores every layout by the relighting PSNR of the fit.rti `rti-rig fit`
writes (as ``benchmarks.adaptive``'s table "of the file a user opens") instead of the normal
error, the starts placed as for ``--objective relight``; its table goes to its own section.

``--families``: instead, from the shipped start, the oracle of wider design families —
completions to more floors, ``optimal`` conditioned on the starting lights (on the surface
fitted to the starting images, ``planner.adaptive_optimal``, or on the benchmark's preview),
and in cells given by ``--ceiling scene:N,...`` a greedy exchange on the true error (slow).

``--truth-surface``: instead, from the shipped start, the fitted design against the same
objective and search on the *true* surface (with and without the objective's model-bias term)
and against a search on the session's own simulated score: which part of the gap is the
surface fitted from 4 images, which the design criterion (docs/adaptive.md, "The fitted surface
or the objective?"; 25 min for 8 draws at load 3-4).

``--object-frame``: instead, from the shipped start, the completions homogeneous about the
object's own mean normal (``benchmarks.adaptive_object_frame``; the median of the object
model's normals, or with ``--true-normal`` the scene's) beside the shipped designs: their true
scores, the oracles with and without them, and the design the session's simulated score takes
with and without them (``--measure relight``: the relight objective's start, designs and score;
``--seed``: fresh draws). Not shipped: docs/adaptive.md, "Homogeneous about the object's mean
normal".

``--preview-start``: instead, the oracle from the start chosen from the preview
(``preview-floor``, :class:`PreviewFloorStart`: 4 lights of the homogeneous layout of N above
the floor whose layout has the least expected error under ``optimal``'s objective from the
benchmark's preview, so that the layout the preview favours stays exactly reachable) beside
the shipped start's, both with and without the fitted design, and the floor chosen per draw
(``--seed``: fresh draws). Not shipped: docs/adaptive.md, "The start chosen from the preview".

Run: ``python -m benchmarks.adaptive_reach [--draws K] [--scenes a,b] [--measure
normals|relight] [--families [--ceiling coin:9,...]] [--write]`` (about 20 s for 8 draws on 2
idle cores, ``--measure relight`` with 16 draws 18 min under load 4, ``--families`` 3 min,
with the ceiling of three cells 10 min; ``--write`` puts the table into docs/adaptive.md).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from benchmarks.report import machine_line, write_section
from rti_rig.app.usecases.adaptive import AdaptiveChooser, dome_start, robust_fit
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner import adaptive
from rti_rig.planner.adaptive import object_model
from rti_rig.planner.adaptive_bias import simulate_designs
from rti_rig.planner.adaptive_optimal import PinnedObjective, pinned_optimal_design
from rti_rig.planner.uniform import select_uniform_leds

DOC = Path(__file__).resolve().parent.parent / "docs" / "adaptive.md"
NS = (6, 9, 12, 18)
FLOORS = adaptive.DESIGN_FLOORS
SIM_REMOVED = 24  # as benchmarks.adaptive
#: Lexicographic weight: a light shared with another floor's layout outranks any angle (rad).
_SHARED_FIRST = 10.0


def hedged_start(
    geometry: DomeGeometry, k: int, n_total: int | None, partners: tuple[float, ...]
) -> list[int]:
    """LED indices of ``k`` starting lights of the default floor's homogeneous layout of
    ``n_total``: first those that also belong to the most layouts above ``partners``, then the
    closest to a homogeneous layout of ``k`` (as ``dome_start``)."""
    if n_total is None or n_total <= k:
        return dome_start(geometry, k, n_total)
    full = np.asarray(select_uniform_leds(geometry, n_total, adaptive.DESIGN_DEFAULT_FLOOR))
    others = [{int(i) for i in select_uniform_leds(geometry, n_total, f)} for f in partners]
    shared = np.array([sum(int(i) in o for o in others) for i in full], dtype=float)
    layout = geometry.directions[full]
    el = np.degrees(np.arcsin(np.clip(layout[:, 2], -1.0, 1.0)))
    lo, hi = max(adaptive.START_FLOOR_DEG, float(el.min())), float(el.max())
    ideal = fibonacci_cap(k, lo, hi) if hi > lo else fibonacci_cap(k, 0.0, 90.0)
    cost = np.arccos(np.clip(ideal @ layout.T, -1.0, 1.0)) - _SHARED_FIRST * shared[None, :]
    _, cols = linear_sum_assignment(cost)
    return [int(full[c]) for c in sorted(cols)]


def shared_three_start(
    geometry: DomeGeometry, k: int, n_total: int | None, objective: str = "normals"
) -> list[int]:
    """3 lights shared by the default floor's and the 20° layouts of ``n_total`` (closest to a
    homogeneous layout of 3), so that both designs stay exactly reachable; where the two share
    fewer than 3, the shipped start of ``k``."""
    if n_total is None or n_total <= k:
        return dome_start(geometry, k, n_total)
    full = select_uniform_leds(geometry, n_total, adaptive.DESIGN_DEFAULT_FLOOR)
    partner = {int(i) for i in select_uniform_leds(geometry, n_total, 20.0)}
    both = np.array([int(i) for i in full if int(i) in partner], dtype=np.intp)
    if both.size < 3:
        return dome_start(geometry, k, n_total)
    pick = adaptive.start_subset(geometry.directions[both], 3)
    return sorted(int(both[i]) for i in pick)


def _start_rule(above_floor: bool):  # type: ignore[no-untyped-def]
    def start(
        geometry: DomeGeometry, k: int, n_total: int | None, objective: str = "normals"
    ) -> list[int]:
        return dome_start(geometry, k, n_total, objective, above_floor=above_floor)

    return start


#: The start matched only among the default layout's lights at or above ``START_FLOOR_DEG``
#: (what ships for ``--objective relight`` since format 9), whatever the objective.
above_floor_start = _start_rule(True)
#: The start matched among all the default layout's lights (what ships for the normals
#: objective; up to format 8 for both): it may take a light below ``START_FLOOR_DEG``.
all_lights_start = _start_rule(False)


def _layout_error(data):  # type: ignore[no-untyped-def]
    """The true mean normal error of a layout (candidate indices) of a rendered scene, scored
    in index order, as benchmarks.adaptive scores every layout."""
    from benchmarks.tradeoff import normal_error

    def err(idx: NDArray[np.intp]) -> float:
        idx = np.sort(idx)
        return normal_error(data.normals, data.candidate_images[idx], data.candidate_dirs[idx])[0]

    return err


def _draw_lights(
    rng: np.random.Generator, count: int, cand: NDArray[np.float64]
) -> tuple[NDArray[np.intp], DomeGeometry]:
    """One draw of benchmarks.adaptive: ``SIM_REMOVED`` candidates out of service."""
    keep = np.sort(rng.choice(count, count - SIM_REMOVED, replace=False))
    return keep, DomeGeometry(cand[keep], tuple(f"c{i:03d}" for i in keep))


def _floor_completions(dirs, start, n: int, floors=FLOORS):  # type: ignore[no-untyped-def]
    """The lights not in ``start`` (indices into ``dirs``, a mask) and the completions of
    ``start`` to each floor's homogeneous layout of ``n`` (None where a floor has none), as a
    session completes its start."""
    avail = np.ones(len(dirs), dtype=bool)
    avail[start] = False
    return avail, [adaptive.homogeneous_completion(dirs, avail, dirs[start], n, f) for f in floors]


def _score_floors(res, n: int, keep, sub: DomeGeometry, err) -> None:  # type: ignore[no-untyped-def]
    """The homogeneous layouts of ``n`` lights above each shipped floor, scored into ``res``."""
    for f in FLOORS:
        res.setdefault((n, f"hom {f:g}"), []).append(err(keep[select_uniform_leds(sub, n, f)]))


#: Extra elevation floors of the ``bands`` family (the shipped designs are ``FLOORS``).
EXTRA_FLOORS = (5.0, 15.0, 25.0, 35.0, 40.0)


@dataclass
class PinnedOptimal:
    """``optimal`` conditioned on the lights already shot: the same objective (from the same
    preview) and exchange search, the shot lights (``pinned``, LED indices) kept, the others
    searched from the completions of the shot lights to each floor's homogeneous layout."""

    pinned: list[int] = field(default_factory=list)
    #: further starting completions (LED indices, the pinned ones excluded)
    extra: list[list[int]] = field(default_factory=list)
    floors: tuple[float, ...] = FLOORS
    name: str = "optimal-pinned"
    summary: str = "optimal with the lights already shot kept (benchmark only)"
    surface: str = "flat"
    needs_preview_reason: str = ""
    optimises_objective: bool = True

    def prepare(self, ctx):  # type: ignore[no-untyped-def]
        return ctx.starts[0][1]

    def decide(self, ctx, objective, chosen):  # type: ignore[no-untyped-def]
        from rti_rig.planner.optimal import exchange_search
        from rti_rig.planner.pixel_bins import binned_objective

        cand = ctx.candidates
        where = {int(led): i for i, led in enumerate(cand.leds)}
        fixed = np.array([where[int(i)] for i in self.pinned], dtype=np.intp)
        avail = np.ones(len(cand.directions), dtype=bool)
        avail[fixed] = False
        starts = []
        for f in self.floors:
            comp = adaptive.homogeneous_completion(
                cand.directions, avail, cand.directions[fixed], ctx.n, f
            )
            if comp is not None:
                starts.append((f"{f:g}", np.asarray(comp, dtype=np.intp)))
        for j, e in enumerate(self.extra):
            starts.append((f"extra {j}", np.array([where[int(i)] for i in e], dtype=np.intp)))
        pinned = PinnedObjective(objective, fixed)
        search = binned_objective(objective)
        res = exchange_search(
            pinned, starts, search=None if search is objective else PinnedObjective(search, fixed)
        )
        return np.r_[fixed, res.chosen]


_PINNED = PinnedOptimal()


def pinned_optimal(
    preview: NDArray,
    geometry: DomeGeometry,
    n: int,
    light: tuple[float, float],
    pinned: list[int],
    extra: list[list[int]] | None = None,
) -> NDArray[np.intp]:
    """LED indices (into ``geometry``) of ``optimal`` for ``n`` lights from ``preview``, the
    ``pinned`` LEDs kept (``extra``: further starting completions, LED indices)."""
    from rti_rig.planner.make_plan import plan_with_report
    from rti_rig.planner.methods import _METHODS, register_method

    if _PINNED.name not in _METHODS:
        register_method(_PINNED)  # type: ignore[arg-type]
    _PINNED.pinned = list(pinned)
    _PINNED.extra = [list(e) for e in (extra or [])]
    sched, _ = plan_with_report(preview, geometry, n, _PINNED.name, "normals", light)
    return np.array([s.led for s in sched.steps], dtype=np.intp)


@dataclass(frozen=True)
class FloorCosts:
    """A planning method that only scores: the expected error, under the objective
    ``optimal`` builds from the preview, of the homogeneous layout at every floor the plan
    starts from (``report.expected`` by label, "uniform ≥F°"); it keeps the user's floor's
    layout (benchmark only: what :class:`PreviewFloorStart` reads)."""

    name: str = "floor-costs"
    summary: str = "the homogeneous layouts scored by optimal's objective (benchmark only)"
    surface: str = "flat"
    needs_preview_reason: str = ""
    optimises_objective: bool = False

    def prepare(self, ctx):  # type: ignore[no-untyped-def]
        return ctx.starts[0][1]

    def decide(self, ctx, objective, chosen):  # type: ignore[no-untyped-def]
        for label, idx in ctx.starts:
            ctx.report.expected[label] = objective.cost(idx)
        return chosen


_FLOOR_COSTS = FloorCosts()


def floor_costs(
    preview: NDArray | None,
    geometry: DomeGeometry,
    n: int,
    light: tuple[float, float] | None,
    objective: str = "normals",
) -> dict[float, float]:
    """The expected error of the homogeneous layout of ``n`` above each of ``FLOORS`` under
    the objective `rti-rig plan --method optimal PREVIEW` builds (the same surface, sample and
    objective; every light of the dome a candidate): {floor: cost}."""
    from rti_rig.planner.make_plan import plan_with_report
    from rti_rig.planner.methods import _METHODS, register_method

    if _FLOOR_COSTS.name not in _METHODS:
        register_method(_FLOOR_COSTS)  # type: ignore[arg-type]
    _, report = plan_with_report(preview, geometry, n, _FLOOR_COSTS.name, objective, light)
    return {f: float(report.expected[f"uniform ≥{f:g}°"]) for f in FLOORS}


def preview_floor(costs: dict[float, float], default: float) -> float:
    """The floor of least expected error; an exact tie goes to ``default`` (then the lower)."""
    return min(costs, key=lambda f: (costs[f], f != default, f))


@dataclass
class PreviewFloorStart:
    """The ``preview-floor`` start: 4 lights of the homogeneous layout of N above the floor
    :func:`preview_floor` picks from the preview (the layout of least expected error under
    ``optimal``'s objective, :func:`floor_costs`), chosen among that layout's lights as the
    shipped start chooses them among the default floor's (``start_subset``) — so that the
    design the preview favours is exactly reachable, the completion to that floor being its
    layout. The rule was fixed before it was measured and has no tuned constant
    (docs/adaptive.md, "The start chosen from the preview"). ``chosen`` logs (N, floor) per
    call. Without a preview (None) the objective is `optimal`'s flat-surface one."""

    preview: NDArray | None = None
    light: tuple[float, float] | None = None
    chosen: list[tuple[int, float]] = field(default_factory=list)
    #: the floors' expected errors behind each choice (as ``chosen``)
    costs: list[dict[float, float]] = field(default_factory=list)

    def __call__(
        self, geometry: DomeGeometry, k: int, n_total: int | None, objective: str = "normals"
    ) -> list[int]:
        if n_total is None or n_total <= k:
            return dome_start(geometry, k, n_total, objective)
        costs = floor_costs(self.preview, geometry, n_total, self.light, objective)
        floor = preview_floor(costs, adaptive.default_floor_for(objective))
        self.chosen.append((n_total, floor))
        self.costs.append(costs)
        full = select_uniform_leds(geometry, n_total, floor)
        pick = adaptive.start_subset(geometry.directions[full], k, objective=objective)
        return sorted(int(full[i]) for i in pick)


def start_functions(
    preview: NDArray | None = None, light: tuple[float, float] | None = None
) -> dict:  # type: ignore[type-arg]
    others = tuple(f for f in FLOORS if f != adaptive.DESIGN_DEFAULT_FLOOR)
    return {
        "default": dome_start,
        # (the objective, passed by benchmarks.adaptive, is ignored: these starts were measured
        # for the normals objective)
        "hedge-all": lambda g, k, n, objective="normals": hedged_start(g, k, n, others),
        "hedge-20": lambda g, k, n, objective="normals": hedged_start(g, k, n, (20.0,)),
        "hedge-10": lambda g, k, n, objective="normals": hedged_start(g, k, n, (10.0,)),
        "shared-3": shared_three_start,
        "above-floor": above_floor_start,
        "all-lights": all_lights_start,
        # the preview's (None: optimal's flat surface), as `rti-rig plan` takes it
        "preview-floor": PreviewFloorStart(preview, light),
    }


def _plain_starts() -> dict:  # type: ignore[type-arg]
    """The starts of the main table: those that need no preview."""
    return {k: v for k, v in start_functions().items() if k != "preview-floor"}


#: What ``reach`` scores a layout by: the true mean normal error (°, lower is better), or the
#: relighting PSNR (dB, higher is better) of the fit.rti `rti-rig fit` writes from it (its HSH
#: order chosen by the fit's own code, ``benchmarks.planner_real_data.written_rti_psnr``) on
#: the lights none of the compared layouts took — as ``benchmarks.adaptive``'s table "of the
#: file a user opens" scores it.
MEASURES = ("normals", "relight")


def _layout_scores(data, measure: str):  # type: ignore[no-untyped-def]
    """``score(layouts: {key: candidate indices}) -> {key: value}`` for one draw and N."""
    if measure == "normals":
        err = _layout_error(data)
        return lambda layouts: {k: err(v) for k, v in layouts.items()}
    from benchmarks.adaptive import common_held_out
    from benchmarks.planner_real_data import written_rti_psnr
    from rti_rig.planner.topography import REC709

    lum = data.candidate_images @ REC709.astype(np.float32)
    cand = data.candidate_dirs

    def psnr(layouts: dict) -> dict:  # type: ignore[type-arg]
        held = common_held_out(len(cand), layouts)
        out = {}
        for k, idx in layouts.items():
            idx = np.sort(idx)  # in index order, as benchmarks.adaptive scores every layout
            out[k] = written_rti_psnr(
                lum[idx], cand[idx], lum[held], cand[held], chosen_on=data.candidate_images[idx]
            )[1]
        return out

    return psnr


def scene_rows(scene: str, res: dict, starts: list[str], measure: str = "normals") -> list[str]:  # type: ignore[type-arg]
    """One scene's table rows from ``res`` ({(N, "hom F" or "start F"): [score per draw]}):
    the bar (the homogeneous layout of the floor best on the mean over N: the lowest error, or
    with ``measure`` "relight" the highest PSNR), each start's completions (mean over draws)
    and its oracle (the best floor per draw), flagged where it falls short of the bar."""
    from benchmarks.adaptive import _tuned_floor

    sign = -1.0 if measure == "relight" else 1.0  # lower sign × score is better
    tuned = _tuned_floor(res, higher_is_better=sign < 0, prefix="hom")
    rows = []
    for n in NS:
        bar = float(np.mean(res[(n, f"hom {tuned:g}")]))
        cells = []
        for name in starts:
            per = np.array([res[(n, f"{name} {f:g}")] for f in FLOORS])  # (F, draws)
            oracle = sign * float((sign * per).min(axis=0).mean())
            fixed = " ".join(f"{v:.3g}" for v in per.mean(axis=1))
            short = sign * oracle > sign * bar + 1e-9 * abs(bar)
            flag = f" **{'below' if sign < 0 else 'above'} the bar**" if short else ""
            cells.append(f"{fixed}; oracle {oracle:.4g}{flag}")
        rows.append(f"| {scene} | {n} | {tuned:g}°: {bar:.4g} | " + " | ".join(cells) + " |")
    return rows


def _scenes(scenes: tuple[str, ...], seed: int):  # type: ignore[no-untyped-def]
    """Per simulated scene asked (all: ``()``): its index, name, rendered data and the draws'
    generator — the draws of benchmarks.adaptive."""
    from benchmarks.tradeoff import TradeoffSettings, render_scene_data

    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    for si, scene in enumerate(settings.scenes):
        if scenes and scene not in scenes:
            continue
        yield si, scene, render_scene_data(scene, settings), np.random.default_rng([seed, si])


def reach(
    draws: int, scenes: tuple[str, ...] = (), seed: int = 0, measure: str = "normals"
) -> list[str]:
    """Table rows: per scene and N, the tuned bar and, per start, each floor's completion (mean
    over draws) and the oracle (``measure``: one of :data:`MEASURES`)."""
    starts = _plain_starts()
    objective = "relight" if measure == "relight" else "normals"
    rows = []
    for _, scene, data, rng in _scenes(scenes, seed):
        cand = data.candidate_dirs
        score = _layout_scores(data, measure)
        res: dict[tuple[int, str], list[float]] = {}
        for _ in range(draws):
            keep, sub = _draw_lights(rng, len(cand), cand)
            for n in NS:
                layouts = {f"hom {f:g}": keep[select_uniform_leds(sub, n, f)] for f in FLOORS}
                for name, fn in starts.items():
                    st = fn(sub, adaptive.START_LIGHTS, n, objective)  # decided after len(st)
                    avail = np.ones(len(keep), dtype=bool)
                    avail[st] = False
                    for f in FLOORS:
                        comp = adaptive.homogeneous_completion(
                            cand[keep], avail, cand[keep][st], n, f
                        )
                        assert comp is not None
                        layouts[f"{name} {f:g}"] = keep[np.r_[st, comp]]
                for k, v in score(layouts).items():
                    res.setdefault((n, k), []).append(v)

        rows += scene_rows(scene, res, list(starts), measure)
        print(f"{scene} done", flush=True)
    return rows


def preview_start(draws: int, scenes: tuple[str, ...] = (), seed: int = 0) -> list[str]:
    """Table rows: per scene and N, the tuned bar, the oracle (best floor's completion per draw,
    decided at the first decision, true mean normal error) from the shipped start and from
    the ``preview-floor`` start (:class:`PreviewFloorStart`, on the benchmark's preview, the
    light `--families` plans `optimal` with), the completion to the floor the preview chose
    (a session that kept it), and the floor chosen per draw."""
    from benchmarks.tradeoff import TradeoffSettings

    light = TradeoffSettings(held_out_lights=1, ground_truth_lights=50).preview_light_az_el_deg
    rows = []
    for _, scene, data, rng in _scenes(scenes, seed):
        cand = data.candidate_dirs
        grey = data.candidate_images.mean(axis=-1)
        err = _layout_error(data)
        starts = {"default": dome_start, "preview": PreviewFloorStart(data.preview, light)}
        res: dict[tuple[int, str], list[float]] = {}
        picked: dict[int, list[float]] = {n: [] for n in NS}
        for _ in range(draws):
            keep, sub = _draw_lights(rng, len(cand), cand)
            for n in NS:
                _score_floors(res, n, keep, sub, err)
                for name, fn in starts.items():
                    st = fn(sub, adaptive.START_LIGHTS, n)
                    _, comps = _floor_completions(cand[keep], st, n)
                    for f, comp in zip(FLOORS, comps, strict=True):
                        assert comp is not None
                        res.setdefault((n, f"{name} {f:g}"), []).append(err(keep[np.r_[st, comp]]))
                    # the fitted design that ships beside the floors, from this start's images
                    state = _start_state(cand[keep], grey[keep], list(st), n)
                    free = pinned_optimal_design(state, cand[keep], np.asarray(st), comps)
                    res.setdefault((n, f"{name} fitted"), []).append(err(keep[np.r_[st, free]]))
                for f, c in starts["preview"].costs[-1].items():
                    res.setdefault((n, f"cost {f:g}"), []).append(c)
                got = starts["preview"].chosen[-1]
                assert got[0] == n
                picked[n].append(got[1])
                res.setdefault((n, "kept"), []).append(res[(n, f"preview {got[1]:g}")][-1])
        tuned = adaptive_tuned(res, 1.0)
        for n in NS:
            bar = float(np.mean(res[(n, f"hom {tuned:g}")]))
            cells = []
            for name in starts:
                per = np.array([res[(n, f"{name} {f:g}")] for f in FLOORS])
                cells.append(float(per.min(axis=0).mean()))
                with_fitted = np.vstack([per, res[(n, f"{name} fitted")]])
                cells.append(float(with_fitted.min(axis=0).mean()))
            cells.append(float(np.mean(res[(n, "kept")])))
            txt = [f"{c:.4g}" + (" **above**" if c > bar * (1 + 1e-9) else "") for c in cells]
            floors = ",".join(f"{f:g}" for f in picked[n])
            true = " / ".join(f"{np.mean(res[(n, f'hom {f:g}')]):.3g}" for f in FLOORS)
            expected = " / ".join(f"{np.mean(res[(n, f'cost {f:g}')]):.3g}" for f in FLOORS)
            rows.append(
                f"| {scene} | {n} | {tuned:g}°: {bar:.4g} | "
                + " | ".join(txt)
                + f" | {floors} | {true} | {expected} |"
            )
        print(f"{scene} done", flush=True)
    return rows


def layout_completion(
    dirs: NDArray[np.float64], layout: NDArray[np.intp], start: list[int]
) -> NDArray[np.intp]:
    """Complete ``start`` towards ``layout`` (indices into ``dirs``): the start's lights take the
    places of the layout's lights nearest them (minimum total angle); the layout's other lights
    are the completion (one already shot replaced by the nearest light not used)."""
    cost = np.arccos(np.clip(dirs[start] @ dirs[layout].T, -1.0, 1.0))
    _, cols = linear_sum_assignment(cost)
    rest = [int(x) for j, x in enumerate(layout) if j not in set(cols.tolist())]
    used = set(start) | set(rest)
    out = []
    for x in rest:
        if x in start:
            free = np.array([i for i in range(len(dirs)) if i not in used])
            x = int(free[np.argmax(dirs[free] @ dirs[x])])
            used.add(x)
        out.append(x)
    return np.array(out, dtype=np.intp)


def families(
    draws: int, scenes: tuple[str, ...] = (), seed: int = 0, ceiling: tuple[str, ...] = ()
) -> list[str]:
    """Table rows: from the shipped start, per scene and N, the tuned bar and the oracle (best
    design per draw, true error) of each family of designs decided at the first decision:
    ``floors`` (what ships: completions above ``FLOORS``), ``bands`` (those and completions
    above ``EXTRA_FLOORS``), ``pinned`` (``optimal`` from the benchmark's preview with the
    starting lights kept: one design), all of them; and unconditioned ``optimal`` (not
    reachable from the start: for reference). ``ceiling`` (cells ``scene:N``): also a greedy
    exchange on the *true* error with the start kept (what any completion could reach; slow)."""
    from benchmarks.planner_real_data import planned_leds
    from benchmarks.tradeoff import TradeoffSettings

    light = TradeoffSettings(held_out_lights=1, ground_truth_lights=50).preview_light_az_el_deg
    rows = []
    for _, scene, data, rng in _scenes(scenes, seed):
        cand = data.candidate_dirs
        grey = data.candidate_images.mean(axis=-1)

        err = _layout_error(data)
        res: dict[tuple[int, str], list[float]] = {}
        for _ in range(draws):
            keep, sub = _draw_lights(rng, len(cand), cand)
            for n in NS:
                _score_floors(res, n, keep, sub, err)
                st = dome_start(sub, adaptive.START_LIGHTS, n)
                avail, every = _floor_completions(cand[keep], st, n, FLOORS + EXTRA_FLOORS)
                for f, comp in zip(FLOORS + EXTRA_FLOORS, every, strict=True):
                    e = np.inf if comp is None else err(keep[np.r_[st, comp]])
                    res.setdefault((n, f"comp {f:g}"), []).append(e)
                state = _start_state(cand[keep], grey[keep], list(st), n)
                comps = every[: len(FLOORS)]
                free = pinned_optimal_design(state, cand[keep], np.asarray(st), comps)
                res.setdefault((n, "fitted"), []).append(err(keep[np.r_[st, free]]))
                opt = planned_leds(data.preview, sub, n, light)
                res.setdefault((n, "optimal"), []).append(err(keep[opt]))
                towards = layout_completion(cand[keep], opt, list(st))
                res.setdefault((n, "towards"), []).append(err(keep[np.r_[st, towards]]))
                pin = pinned_optimal(data.preview, sub, n, light, list(st), [list(towards)])
                assert set(st) <= {int(i) for i in pin} and len(pin) == n
                res.setdefault((n, "pinned"), []).append(err(keep[pin]))
                if f"{scene}:{n}" in ceiling:
                    best = min(FLOORS, key=lambda f: res[(n, f"comp {f:g}")][-1])
                    start = adaptive.homogeneous_completion(
                        cand[keep], avail, cand[keep][st], n, best
                    )
                    res.setdefault((n, "ceiling"), []).append(
                        _true_greedy(err, keep, np.asarray(st), np.asarray(start), avail)
                    )
        tuned = min(FLOORS, key=lambda f: np.mean([np.mean(res[(n, f"hom {f:g}")]) for n in NS]))
        for n in NS:
            bar = float(np.mean(res[(n, f"hom {tuned:g}")]))

            def oracle(labels: list[str], n=n, res=res) -> float:  # type: ignore[no-untyped-def]
                return float(np.array([res[(n, x)] for x in labels]).min(axis=0).mean())

            shipped = [f"comp {f:g}" for f in FLOORS]
            bands = shipped + [f"comp {f:g}" for f in EXTRA_FLOORS]
            cells = [
                oracle(shipped),
                oracle(bands),
                float(np.mean(res[(n, "fitted")])),
                oracle([*shipped, "fitted"]),
                float(np.mean(res[(n, "towards")])),
                float(np.mean(res[(n, "pinned")])),
                oracle([*shipped, "towards", "pinned"]),
                oracle([*bands, "fitted", "towards", "pinned"]),
            ]
            txt = [f"{c:.3g}" + (" **above**" if c > bar * (1 + 1e-9) else "") for c in cells]
            extra = " ".join(
                f"{f:g}°: {np.mean(res[(n, f'comp {f:g}')]):.3g}" for f in EXTRA_FLOORS
            )
            ceil = f"{np.mean(res[(n, 'ceiling')]):.3g}" if (n, "ceiling") in res else "–"
            rows.append(
                f"| {scene} | {n} | {tuned:g}°: {bar:.3g} | "
                + " | ".join(txt)
                + f" | {extra} | {np.mean(res[(n, 'optimal')]):.3g} | {ceil} |"
            )
        print(f"{scene} done", flush=True)
    return rows


#: Pixels of the true surface the ``--truth-surface`` objective is evaluated on (an even
#: random sample of the pixels with a true normal; a session searches 500 of its fit's).
TRUTH_PIXELS = 500


def true_surface_sample(data, keep: NDArray[np.intp], pixels: NDArray[np.intp]):  # type: ignore[no-untyped-def]
    """The objective's surface sample from the *truth*: the scene's true normals at ``pixels``
    and, per light kept, how lit each pixel really is, read from the rendered images: the
    observation over the Lambertian shading of its true normal, over the pixel's albedo (the
    median of that ratio over its lights with shading above 0.3), clipped to [0, 1]. Cast
    shadows, interreflection and gloss are in it as the camera saw them (with its noise);
    what a session could at best know of its object after every light."""
    from rti_rig.planner.objectives import SurfaceSample

    normals = data.normals.reshape(-1, 3)[pixels].astype(np.float64)
    grey = data.candidate_images[keep].mean(axis=-1).reshape(len(keep), -1)[:, pixels].T
    shade = np.clip(normals @ data.candidate_dirs[keep].T, 0.0, None)
    ratio = grey / np.maximum(shade, 1e-6)
    albedo = np.nanmedian(np.where(shade > 0.3, ratio, np.nan), axis=1)
    lit = np.clip(np.nan_to_num(ratio / albedo[:, None]), 0.0, 1.0) * (shade > 0)
    p = len(normals)
    return SurfaceSample(
        normals=normals,
        weights=np.ones(p),
        lit_candidates=lit,
        held_out=np.zeros((0, 3)),
        lit_held_out=np.zeros((p, 0)),
    )


def truth_surface(
    draws: int, scenes: tuple[str, ...] = (), seed: int = 0, ceiling: tuple[str, ...] = ()
) -> list[str]:
    """Table rows: from the shipped start at the first decision, the true error of the fitted
    design (what ships: ``optimal``'s objective on the surface fitted to the 4 starting images)
    against the same objective and search on the *true* surface (:func:`true_surface_sample`),
    each with and without the objective's model-bias term — which part of the gap to the bar
    is the surface a session has fitted, which the objective itself — and, in ``ceiling``
    cells, the greedy exchange on the true error."""
    import rti_rig.planner.adaptive_optimal as ao
    from rti_rig.planner.objectives import Candidates, NormalsObjective

    rows = []
    for si, scene, data, rng in _scenes(scenes, seed):
        cand = data.candidate_dirs
        grey = data.candidate_images.mean(axis=-1)
        finite = np.flatnonzero(np.isfinite(data.normals.reshape(-1, 3)).all(axis=1))
        pixels = np.sort(np.random.default_rng([seed, si, 1]).choice(finite, TRUTH_PIXELS, False))
        err = _layout_error(data)
        res: dict[tuple[int, str], list[float]] = {}
        for _ in range(draws):
            keep, sub = _draw_lights(rng, len(cand), cand)
            truth = true_surface_sample(data, keep, pixels)
            for n in NS:
                _score_floors(res, n, keep, sub, err)
                st = np.asarray(dome_start(sub, adaptive.START_LIGHTS, n))
                avail, comps = _floor_completions(cand[keep], st, n)
                state = _start_state(cand[keep], grey[keep], list(st), n)
                fitted = ao.state_sample(ao._subsample(state, TRUTH_PIXELS), cand[keep])
                everything = np.ones(len(keep), dtype=bool)
                for label, sample in (("fitted", fitted), ("truth", truth)):
                    for bias, tag in ((None, ""), (0.0, " no bias")):
                        kw = {} if bias is None else {"bias_rel": bias}
                        obj = NormalsObjective(sample, Candidates(cand[keep], None, None), **kw)
                        free = ao.pinned_search(obj, st, everything, comps)
                        res.setdefault((n, label + tag), []).append(err(keep[np.r_[st, free]]))
                # the chooser's own score: the robust fit simulated on the object model
                model = object_model(state)
                shipped = [*comps, ao.pinned_optimal_design(state, cand[keep], st, comps)]
                sims = simulate_designs(
                    model,
                    [np.concatenate([cand[keep][st], cand[keep][c]]) for c in shipped],
                    robust_fit,
                )
                chosen = shipped[int(np.argmin(sims))]
                res.setdefault((n, "simulated best"), []).append(err(keep[np.r_[st, chosen]]))
                searched = _simulated_search(model, cand[keep], st, chosen, float(min(sims)))
                res.setdefault((n, "simulated search"), []).append(err(keep[np.r_[st, searched]]))
                if f"{scene}:{n}" in ceiling:
                    best = min(comps, key=lambda c: err(keep[np.r_[st, c]]))
                    res.setdefault((n, "ceiling"), []).append(
                        _true_greedy(err, keep, st, np.asarray(best), avail)
                    )
        tuned = min(FLOORS, key=lambda f: np.mean([np.mean(res[(n, f"hom {f:g}")]) for n in NS]))
        for n in NS:
            bar = float(np.mean(res[(n, f"hom {tuned:g}")]))
            cells = []
            for label in (
                "fitted",
                "fitted no bias",
                "truth",
                "truth no bias",
                "simulated best",
                "simulated search",
                "ceiling",
            ):
                if (n, label) not in res:
                    cells.append("–")
                    continue
                v = float(np.mean(res[(n, label)]))
                cells.append(f"{v:.3g}" + (" **above**" if v > bar * (1 + 1e-9) else ""))
            rows.append(f"| {scene} | {n} | {tuned:g}°: {bar:.3g} | " + " | ".join(cells) + " |")
        print(f"{scene} done", flush=True)
    return rows


def object_frame(
    draws: int,
    scenes: tuple[str, ...] = (),
    seed: int = 0,
    measure: str = "normals",
    true_normal: bool = False,
) -> list[str]:
    """Table rows: from the shipped start at the first decision, the homogeneous completions
    about the object's mean normal (``benchmarks.adaptive_object_frame``, the normal the median
    of the object model's normals) beside the shipped designs (the floors' completions and
    the fitted design): their true scores, the oracle with and without them, and the design
    the session's own score takes (the robust fit simulated on the object model, the default
    floor kept unless another is ``SIM_MARGIN`` better, as ``choose_in_design`` takes it)
    with and without them. ``measure`` "relight" scores the layouts by the written fit.rti's
    PSNR, the start and the simulated choice the relight objective's. ``true_normal``: the
    layouts about the scene's true median normal instead (what a perfect estimate would give).
    A last row per scene gives the normal's tilt from the camera axis (median, range over
    draws and N)."""
    import rti_rig.planner.adaptive_optimal as ao
    from benchmarks import adaptive_object_frame as aof

    sign = -1.0 if measure == "relight" else 1.0
    rows = []
    for _, scene, data, rng in _scenes(scenes, seed):
        cand = data.candidate_dirs
        grey = data.candidate_images.mean(axis=-1)
        score = _layout_scores(data, measure)
        res: dict[tuple[int, str], list[float]] = {}
        tilts: list[float] = []
        for _ in range(draws):
            keep, sub = _draw_lights(rng, len(cand), cand)
            for n in NS:
                layouts = {f"hom {f:g}": keep[select_uniform_leds(sub, n, f)] for f in FLOORS}
                objective = "relight" if measure == "relight" else "normals"
                st = np.asarray(dome_start(sub, adaptive.START_LIGHTS, n, objective))
                avail, comps = _floor_completions(cand[keep], st, n)
                state = _start_state(cand[keep], grey[keep], list(st), n)
                model = object_model(state)
                normal = aof.mean_normal(data.normals if true_normal else model.normals)
                tilts.append(aof.tilt_deg(normal))
                designs = {f: c for f, c in zip(FLOORS, comps, strict=True)}
                if measure == "relight":
                    fitted = adaptive._fitted_relight(model, state, cand[keep], avail, designs, n)
                else:
                    fitted = ao.pinned_optimal_design(state, cand[keep], st, comps)
                if fitted is not None:
                    designs[adaptive.FITTED_KEY] = fitted
                obj = {}
                for f in FLOORS:
                    c = aof.object_frame_completion(cand[keep], avail, cand[keep][st], n, f, normal)
                    if c is not None and c.size:
                        obj[100.0 + f] = c
                every = {**designs, **obj}
                full = [np.concatenate([cand[keep][st], cand[keep][c]]) for c in every.values()]
                d0 = adaptive.default_floor_for(objective)
                if measure == "relight":
                    pick, pick_obj = (
                        _relight_pick(model, cand[keep], avail, every, full, n, keys, d0)
                        for keys in (list(designs), list(every))
                    )
                else:
                    sims = dict(zip(every, simulate_designs(model, full, robust_fit), strict=True))
                    pick = adaptive._switch(
                        {k: sims[k] for k in designs}, d0, adaptive.SIM_MARGIN, None
                    )
                    pick_obj = adaptive._switch(sims, d0, adaptive.SIM_MARGIN, None)
                for k, c in every.items():
                    layouts[f"d {k:g}"] = keep[np.r_[st, c]]
                got = score(layouts)
                for k, v in got.items():
                    res.setdefault((n, k), []).append(v)
                for k in FLOORS:
                    res.setdefault((n, f"of {k:g}"), []).append(
                        got.get(f"d {100.0 + k:g}", sign * np.inf)
                    )
                res.setdefault((n, "pick"), []).append(got[f"d {pick:g}"])
                res.setdefault((n, "pick obj"), []).append(got[f"d {pick_obj:g}"])
                res.setdefault((n, "took obj"), []).append(float(pick_obj >= 100.0))
        tuned = adaptive_tuned(res, sign)
        for n in NS:
            bar = float(np.mean(res[(n, f"hom {tuned:g}")]))

            def oracle(labels: list[str], n=n, res=res) -> float:  # type: ignore[no-untyped-def]
                return sign * float(
                    (sign * np.array([res[(n, x)] for x in labels])).min(axis=0).mean()
                )

            shipped = [f"d {k:g}" for k in (*FLOORS, adaptive.FITTED_KEY) if (n, f"d {k:g}") in res]
            objs = [f"of {k:g}" for k in FLOORS]
            cells = [
                *(float(np.mean(res[(n, x)])) for x in objs),
                oracle(shipped),
                oracle(shipped + objs),
                float(np.mean(res[(n, "pick")])),
                float(np.mean(res[(n, "pick obj")])),
            ]
            txt = [
                f"{c:.3g}" + (" **worse**" if sign * c > sign * bar * (1 + 1e-9 * sign) else "")
                for c in cells
            ]
            took = int(np.sum(res[(n, "took obj")]))
            rows.append(
                f"| {scene} | {n} | {tuned:g}°: {bar:.3g} | "
                + " | ".join(txt)
                + f" | {took}/{draws} |"
            )
        print(
            f"{scene} done; estimated tilt {np.median(tilts):.1f}° "
            f"({np.min(tilts):.1f}-{np.max(tilts):.1f})",
            flush=True,
        )
        spread = f"{np.median(tilts):.1f}° ({np.min(tilts):.1f}–{np.max(tilts):.1f})"
        rows.append(f"| {scene} | estimated tilt | {spread} |" + " |" * 9)
    return rows


def _relight_pick(model, dirs, avail, every, full, n, keys, keep_floor):  # type: ignore[no-untyped-def]
    """The design among ``keys`` the relight objective's simulated score takes (its margin and
    default, the lights none of them takes held out), as ``choose_in_design`` takes it."""
    from rti_rig.app.usecases.adaptive import relight_fit
    from rti_rig.planner.adaptive_relight import (
        pick_floor,
        relight_basis,
        shared_held_out,
        simulate_relight_designs,
    )

    order = list(every)
    held, _ = shared_held_out(dirs, avail, [every[k] for k in keys])
    got = simulate_relight_designs(
        model, [full[order.index(k)] for k in keys], held, relight_fit, relight_basis(n)
    )
    return pick_floor(dict(zip(keys, got, strict=True)), keep_floor)


def adaptive_tuned(res, sign: float) -> float:  # type: ignore[no-untyped-def]
    """The hindsight-tuned floor: the homogeneous layout best on the mean over N."""
    return min(FLOORS, key=lambda f: sign * np.mean([np.mean(res[(n, f"hom {f:g}")]) for n in NS]))


def _simulated_search(model, dirs, shot, start, score: float, sweeps: int = 2):  # type: ignore[no-untyped-def]
    """Single-light exchanges of the lights not shot (``start``), each replaced by the light
    (any not shot) that lowers the chooser's *simulated* error most (the robust fit simulated
    on the object model, ``simulate_designs``), ``sweeps`` sweeps: what searching the design
    on the session's own score, rather than on ``optimal``'s objective, could give."""
    free = [int(i) for i in start]
    others = np.setdiff1d(np.arange(len(dirs)), shot)
    for _ in range(sweeps):
        for pos in range(len(free)):
            trials = []
            for c in others:
                if int(c) not in free:
                    t = free.copy()
                    t[pos] = int(c)
                    trials.append(t)
            sims = simulate_designs(
                model, [np.concatenate([dirs[shot], dirs[t]]) for t in trials], robust_fit
            )
            j = int(np.argmin(sims))
            if sims[j] < score:
                score, free = float(sims[j]), trials[j]
    return np.asarray(free, dtype=np.intp)


#: The ``ceiling`` tries every CEILING_STRIDE-th available light at each position (offset by
#: the position), so one sweep costs (N - 4) × 216 / CEILING_STRIDE robust fits.
CEILING_STRIDE = 3


def _start_state(dirs, grey, start: list[int], n: int):  # type: ignore[no-untyped-def]
    """The chooser's surface state after the starting images (what the first decision sees)."""
    chooser = AdaptiveChooser(dirs, start, n, None, design_lights=n)
    for i in range(len(start)):
        c, _ = chooser.decide(i)
        assert c is not None
        chooser.observe(c, dirs[c], grey[c])
    return chooser.state()


def _true_greedy(err, keep, st, start, avail, sweeps: int = 1) -> float:  # type: ignore[no-untyped-def]
    """The true error after single-light exchanges of the lights not shot (``start``: a
    completion), each replaced by the tried light that lowers the *true* error most, for
    ``sweeps`` sweeps: a stand-in for the best any completion of the start reaches."""
    free = list(start)
    cur = err(keep[np.r_[st, free]])
    for _ in range(sweeps):
        for pos in range(len(free)):
            used = set(free)
            for c in np.flatnonzero(avail)[pos % CEILING_STRIDE :: CEILING_STRIDE]:
                if int(c) in used:
                    continue
                trial = free.copy()
                trial[pos] = int(c)
                e = err(keep[np.r_[st, trial]])
                if e < cur:
                    cur, best_c = e, int(c)
                    free[pos] = best_c
                    used = set(free)
    return cur


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--draws", type=int, default=8)
    ap.add_argument("--scenes", default="", help="comma-separated simulated scenes (default all)")
    ap.add_argument("--write", action="store_true", help="write the table into docs/adaptive.md")
    ap.add_argument(
        "--families",
        action="store_true",
        help="instead: the oracle of wider design families from the shipped start",
    )
    ap.add_argument(
        "--ceiling",
        default="",
        help="with --families: cells scene:N (comma-separated) that also get a greedy exchange "
        "on the true error (slow)",
    )
    ap.add_argument(
        "--truth-surface",
        action="store_true",
        help="instead: the fitted design against the same objective on the true surface, "
        "with and without its model-bias term (which part of the gap is the fitted surface)",
    )
    ap.add_argument(
        "--object-frame",
        action="store_true",
        help="instead: completions homogeneous about the object's mean normal beside the "
        "shipped designs (their reach and the session's simulated choice)",
    )
    ap.add_argument(
        "--preview-start",
        action="store_true",
        help="instead: the oracle from the start chosen from the preview (preview-floor) "
        "beside the shipped start's, and the floor chosen per draw",
    )
    ap.add_argument(
        "--true-normal",
        action="store_true",
        help="with --object-frame: the layouts about the scene's true mean normal",
    )
    ap.add_argument(
        "--seed",
        type=int,
        default=0,
        help="with --object-frame or --preview-start: the draws (0: those of the tables; "
        "another: fresh draws)",
    )
    ap.add_argument(
        "--measure",
        choices=MEASURES,
        default="normals",
        help="score layouts by normal error (default) or by the relighting PSNR of the fit.rti "
        "`rti-rig fit` writes",
    )
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    if args.families:
        return _families_main(args, t0)
    if args.truth_surface:
        return _truth_main(args, t0)
    if args.object_frame:
        return _object_frame_main(args, t0)
    if args.preview_start:
        return _preview_start_main(args, t0)
    rows = reach(args.draws, tuple(x for x in args.scenes.split(",") if x), measure=args.measure)
    floors = "/".join(f"{f:g}°" for f in FLOORS)
    starts = list(_plain_starts())
    what = (
        "the true mean normal error (°)"
        if args.measure == "normals"
        else "the relighting PSNR (dB) of the fit.rti `rti-rig fit` writes (its HSH order "
        "chosen by the fit's own code; on the lights none of the compared layouts took)"
    )
    option = "" if args.measure == "normals" else f" --measure {args.measure}"
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.adaptive_reach --draws {args.draws}{option} --write` "
            f"({time.perf_counter() - t0:.0f} s; load average {os.getloadavg()[0]:.1f} at the "
            "end). " + machine_line(),
            "",
            f"Simulator, {args.draws} paired draws (the draws of `benchmarks.adaptive`). Per "
            f"start: {what} of the design completed above {floors} when "
            "decided at the first decision (after the starting lights: 4 images, 3 for "
            "`shared-3` where it applies), then the oracle (the best floor per draw: a "
            "perfect model). The bar: the hindsight-tuned homogeneous layout. `default` is "
            "the start that ships for the measure's objective; `above-floor` matches the start "
            f"only among the default layout's lights at or above {adaptive.START_FLOOR_DEG:g}° "
            "(what ships for relighting), `all-lights` among all of them (what ships for "
            "normals, and up to format 8 for both).",
            "",
            "| scene | N | bar | " + " | ".join(f"start `{s}`" for s in starts) + " |",
            "|---|---|---|" + "---|" * len(starts),
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section(
            "adaptive_reach" if args.measure == "normals" else f"adaptive_reach_{args.measure}",
            md,
            DOC,
        )
    return md


def _families_main(args: argparse.Namespace, t0: float) -> str:
    import rti_rig.planner.adaptive_optimal as adaptive_optimal

    # the family's reach is measured searching every sampled pixel, as its table in
    # docs/adaptive.md was (a session searches SEARCH_PIXELS = 500 of them)
    adaptive_optimal.SEARCH_PIXELS = None
    ceiling = tuple(x for x in args.ceiling.split(",") if x)
    rows = families(args.draws, tuple(x for x in args.scenes.split(",") if x), ceiling=ceiling)
    extra = "/".join(f"{f:g}°" for f in EXTRA_FLOORS)
    md = "\n".join(
        [
            _command_line("--families", args, ceiling, t0),
            "",
            f"Simulator, {args.draws} paired draws (those of `benchmarks.adaptive`), the shipped "
            "start (4 lights), designs decided at the first decision. Per family, the oracle "
            "(true mean normal error, °, of the best design of the family per draw): "
            f"`floors` — completions above {'/'.join(f'{f:g}°' for f in FLOORS)} (what ships); "
            f"`bands` — those and completions above {extra}; `fitted` — one design: "
            "`optimal`'s objective "
            "on the surface fitted to the 4 starting images (what a session knows: "
            "`planner.adaptive_optimal`), exchange search with the starting lights kept, from "
            "the shipped completions; `floors+fitted` — the best of `floors` and `fitted`; "
            "the next three use the benchmark's preview (a session has none): `towards` — one "
            "design: the start "
            "completed towards the benchmark's `optimal` layout (its lights nearest the start's "
            "replaced by them); `pinned` — one design: `optimal` (same preview, objective and "
            "exchange search) with the 4 starting lights kept, searched from the shipped "
            "completions and `towards`; `floors+preview` — the best of `floors`, `towards` "
            "and `pinned`; `all` — the best of every design above. Then the "
            "extra floors' completions alone (means), unconditioned `optimal` (not reachable "
            "from the start; for reference) and, where measured, the `ceiling`: single-light "
            "exchanges of the lights not shot on the *true* error (one sweep from the best "
            f"shipped completion, every {CEILING_STRIDE}rd available light tried at each "
            "place). **above**: above the bar (the hindsight-tuned homogeneous "
            "layout).",
            "",
            "| scene | N | bar | `floors` (ships) | `bands` | `fitted` | `floors+fitted` | "
            "`towards` | `pinned` | `floors+preview` | `all` | extra floors alone | `optimal` | "
            "`ceiling` |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section("adaptive_reach_families", md, DOC)
    return md


def _command_line(mode: str, args: argparse.Namespace, ceiling: tuple[str, ...], t0: float) -> str:
    """The table's first line: the command that measured it, how long, at what load, where."""
    return (
        f"Command: `python -m benchmarks.adaptive_reach {mode} --draws {args.draws}"
        + (f" --ceiling {args.ceiling}" if ceiling else "")
        + (f" --scenes {args.scenes}" if args.scenes else "")
        + (" --write" if args.write else "")
        + f"` ({time.perf_counter() - t0:.0f} s; load average {os.getloadavg()[0]:.1f} at "
        "the end). " + machine_line()
    )


def _truth_main(args: argparse.Namespace, t0: float) -> str:
    ceiling = tuple(x for x in args.ceiling.split(",") if x)
    scenes = tuple(x for x in args.scenes.split(",") if x)
    rows = truth_surface(args.draws, scenes, ceiling=ceiling)
    md = "\n".join(
        [
            _command_line("--truth-surface", args, ceiling, t0),
            "",
            f"Simulator, {args.draws} paired draws (those of `benchmarks.adaptive`), the shipped "
            "start (4 lights), the design decided at the first decision; true mean normal error "
            "(°). `fitted`: the fitted design as it ships (`optimal`'s objective on the surface "
            f"fitted to the 4 starting images, {TRUTH_PIXELS} of its pixels); `truth`: the same "
            f"objective and exchange search on the true surface ({TRUTH_PIXELS} pixels: true "
            "normals, and how lit each pixel is read from the rendered images); `no bias`: "
            "the objective's model-bias term off. `simulated best`: of the floors' completions "
            "and `fitted`, the design the session's own score ranks first (the robust fit "
            "simulated on the object model of the 4 images, as the chooser scores designs; "
            "without its margin); `simulated search`: single-light exchanges from it of the "
            "lights not shot, any light not shot tried, 2 sweeps, on that simulated score. "
            "`ceiling` where measured (as in the families table). **above**: above the bar "
            "(the hindsight-tuned homogeneous layout).",
            "",
            "| scene | N | bar | `fitted` (ships) | `fitted`, no bias | `truth` | `truth`, no bias "
            "| simulated best | simulated search | `ceiling` |",
            "|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section("adaptive_reach_truth", md, DOC)
    return md


def _preview_start_main(args: argparse.Namespace, t0: float) -> str:
    scenes = tuple(x for x in args.scenes.split(",") if x)
    rows = preview_start(args.draws, scenes, seed=args.seed)
    md = "\n".join(
        [
            _command_line(
                "--preview-start" + (f" --seed {args.seed}" if args.seed else ""), args, (), t0
            ),
            "",
            f"Simulator, {args.draws} paired draws (those of `benchmarks.adaptive`"
            + (f", seed {args.seed}" if args.seed else "")
            + "), designs decided at the first decision; true mean normal error (°). Oracle: "
            f"the best of the completions above {'/'.join(f'{f:g}°' for f in FLOORS)} per "
            "draw, from the shipped start (4 lights of the 10° layout) and from `preview-floor` "
            "(4 lights of the layout of the floor whose homogeneous layout of N has the least "
            "expected error under `optimal`'s normals objective from the benchmark's preview); "
            "`+fitted`: the oracle with the fitted design that ships beside the floors "
            "(`planner.adaptive_optimal`, on the surface fitted to that start's 4 images); "
            "`kept`: the completion to the floor the preview chose (its layout exactly); the "
            "floors chosen per draw; then per floor 0/10/20/30° the homogeneous layout's true "
            "error and its expected error under the preview's objective (what the rule ranks; "
            "means over draws). **above**: above the bar (the hindsight-tuned homogeneous "
            "layout).",
            "",
            "| scene | N | bar | oracle, shipped start | +fitted | oracle, `preview-floor` | "
            "+fitted | `kept` | floor chosen per draw | homogeneous, true | homogeneous, "
            "expected |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section(
            "adaptive_reach_preview_start" + (f"_seed{args.seed}" if args.seed else ""), md, DOC
        )
    return md


def _object_frame_main(args: argparse.Namespace, t0: float) -> str:
    scenes = tuple(x for x in args.scenes.split(",") if x)
    rows = object_frame(
        args.draws, scenes, seed=args.seed, measure=args.measure, true_normal=args.true_normal
    )
    unit = (
        "true mean normal error (°)" if args.measure == "normals" else "written fit.rti PSNR (dB)"
    )
    md = "\n".join(
        [
            _command_line(
                "--object-frame"
                + (" --true-normal" if args.true_normal else "")
                + (f" --seed {args.seed}" if args.seed else "")
                + ("" if args.measure == "normals" else f" --measure {args.measure}"),
                args,
                (),
                t0,
            ),
            "",
            f"Simulator, {args.draws} paired draws (those of `benchmarks.adaptive`), the shipped "
            f"start, the design decided at the first decision; {unit}. `obj F`: the start "
            "completed to the layout homogeneous above F° from the plane whose normal is the "
            + (
                "scene's true median normal"
                if args.true_normal
                else "median of the object model's normals"
            )
            + " (`benchmarks.adaptive_object_frame`; a light shot behind that plane holds no "
            "place of the layout); oracles (best per draw) of the shipped "
            "designs (floors' completions and the fitted design) and of those with the `obj` "
            "ones; `pick`: the design the session's simulated score takes (margin and default "
            "as `choose_in_design`), without and with the `obj` designs offered, and how often "
            "it took one. **worse**: worse than the bar (the hindsight-tuned homogeneous layout).",
            "",
            "| scene | N | bar | obj 0 | obj 10 | obj 20 | obj 30 | oracle shipped | oracle "
            "+obj | pick shipped | pick +obj | took obj |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section("adaptive_reach_object_frame", md, DOC)
    return md


if __name__ == "__main__":
    main(sys.argv[1:])
