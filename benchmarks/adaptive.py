"""Adaptive acquisition against `optimal` and the hindsight-tuned homogeneous layout.

Paired draws (``benchmarks.paired``): in each draw some candidate lights are out of service and
every strategy works on the same remaining ones:

* **homogeneous**, floor tuned with hindsight (the floor with the lowest mean error over the
  draws and N, per scene) — the bar;
* **optimal** (``plan --method optimal``, objective normals, from one preview);
* **adaptive** (``run --adaptive``: the same :class:`AdaptiveChooser` the CLI runs, fed the
  images of the lights it picks), as ``run --adaptive --lights N``: with N known the design is
  chosen for N, so each N is its own session. Each is run twice: with the normals objective
  (the default; scored in the normals table) and with ``--objective relight`` (scored in the
  relighting table, where the normals-objective session's PSNR is shown beside it).

Scored as the other planner benchmarks score: normal error of robust photometric stereo (sim:
against the true normals, every pixel; real: against the all-light fit, on the object mask) and
relighting PSNR on **one held-out set per draw and N, the same for every strategy**, twice:
of the richest basis N lights determine (what the relight objective's designs are scored by)
and of the fit.rti `rti-rig fit` writes (its HSH order chosen on held-out lights, as the fit
chooses it: ``planner_real_data.written_rti_psnr``; what a user opens). The held-out set
is the candidates none of the compared layouts took (the lights out of service included).
Before 2026-11-24 each layout was scored on the lights *it* did not take, so two layouts were
compared on different lights (a layout that took the grazing lights was judged on easier
ones); the tables of that time are kept in docs/adaptive.md with that caveat.

The stopping rule's estimate is calibrated here: the raw estimate (the robust fit simulated on
the object's model, ``AdaptiveChooser.raw_estimate``) against the measured error of the
adaptive layouts on the simulator, ``log(measured/raw) = log(scale) + slope × discarded
fraction`` by least squares over scenes, draws and N — the gloss-aware slope
kept only if it predicts left-out scenes better than one global factor (slope 0). Each scene's
predicted error is shown with the factors fitted on the *other* scenes (leave one scene out),
then on the real dome (never used for the fit). ``--until-error``: lights used and measured
error per scene and target.

Run: ``python -m benchmarks.adaptive [--sim-draws K] [--real-draws K] [--scenes a,b] [--seed S]
[--ns 6,9] [--no-until] [--start default|hedge-all|hedge-20|hedge-10|shared-3]
[--floors F,F] [--default-floor F] [--relight-default-floor F] [--relief-gain]
[--no-fitted-design] [--fitted-margin M] [--heldout-score select|1se|mean|minimax|variant-NAME]
[--fitted-seeds F,F] [--sim-margin M] [--fitted-pixels K] [--no-relight-fitted-design]
[--relight-basis B]
[--no-relight] [--cache FILE] [--min-elevation-deg F] [--max-elevation-deg C]
[--write]`` (the real acquisition is read from ../shared/data/neuralrti-example beside the
repository; ``--cache`` keeps `optimal`'s layouts between runs; ``--write`` puts the tables into
docs/adaptive.md).

**Within a band** (``--min-elevation-deg F`` / ``--max-elevation-deg C``, as ``run --adaptive``
takes them): adaptive's candidates and starting lights are the CLI's own
(:func:`rti_rig.app.usecases.adaptive.adaptive_plan`), `optimal` is planned with the band, and
the bar is tuned over the homogeneous layouts ``plan --method uniform`` builds within it, above
0/10/20/30° raised to the band's floor (:func:`bar_floors`). The tables go to their own section
of docs/adaptive.md (``adaptive_band_max45`` …; ``--sim-draws 0 --real-draws K``: the real dome
alone, ``…_real``); no calibration or ``--until-error`` rows (those are every elevation's).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.metrics import relight_psnr
from benchmarks.paired import compare
from benchmarks.planner_real_data import relight_model, written_rti_psnr
from benchmarks.report import machine_line, write_section
from rti_rig.app.usecases.adaptive import AdaptiveChooser, dome_start, small_grey
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.adaptive import SIM_ESTIMATE_SCALE, START_LIGHTS, discarded_fraction
from rti_rig.planner.adaptive_until import UPPER_FACTOR
from rti_rig.planner.objectives import models_for
from rti_rig.planner.topography import REC709
from rti_rig.planner.uniform import select_uniform_leds

DOC = Path(__file__).resolve().parent.parent / "docs" / "adaptive.md"
NS = (6, 9, 12, 18)
FLOORS = (0.0, 10.0, 20.0, 30.0)
SIM_REMOVED = 24
REAL_REMOVED = 8
TARGETS_DEG = (1.0, 2.0, 4.0)
#: Whether adaptive runs with N known choose a design of N as a whole (as the CLI does).
DESIGN = True
#: The starting lights with N known (``--start``: what ships, or a start of
#: ``benchmarks.adaptive_reach``, to measure it; nothing but this benchmark uses the others).
START = {"start": dome_start}
#: Whether the simulator's ``--objective relight`` sessions are run (``--no-relight``: not,
#: to iterate on the normals objective faster; the relighting table is then not a result).
RELIGHT = True
#: The elevation band (°, low and high) every strategy keeps to (``--min/--max-elevation-deg``;
#: None: every elevation, the main tables). With a band, adaptive is planned by the CLI's own
#: :func:`~rti_rig.app.usecases.adaptive.adaptive_plan` (``run --adaptive
#: --min/--max-elevation-deg``), the bar's homogeneous layouts and `optimal` by ``plan --method
#: uniform|optimal --min/--max-elevation-deg`` (:func:`bar_floors` says which floors).
BAND: tuple[float, float] | None = None


def bar_floors(band: tuple[float, float] | None = None) -> tuple[float, ...]:
    """The floors of the bar's homogeneous layouts: :data:`FLOORS`, each raised to the band's
    floor (0° and 10° under a 20° floor are the 20° layout: kept once) and dropped where it
    leaves no band below the ceiling (``band`` None: :data:`BAND`) — the floors an adaptive
    session's designs take in that band (its completions above ``DESIGN_FLOORS`` among the
    band's lights), so the bar is tuned over the layouts adaptive can end with."""
    band = BAND if band is None else band
    if band is None:
        return FLOORS
    lo, hi = band
    return tuple(sorted({max(f, lo) for f in FLOORS if max(f, lo) < hi}))


def bar_layout(geometry: DomeGeometry, n: int, floor: float) -> np.ndarray:
    """The homogeneous layout of ``n`` above ``floor`` (LED indices into ``geometry``, in index
    order); within :data:`BAND`, as ``rti-rig plan --method uniform --min-elevation-deg FLOOR
    --max-elevation-deg CEILING`` builds it."""
    if BAND is None:
        return select_uniform_leds(geometry, n, floor)
    from rti_rig.planner.make_plan import plan_with_report

    sched, _ = plan_with_report(
        None, geometry, n, "uniform", "normals", min_elevation_deg=floor, max_elevation_deg=BAND[1]
    )
    return np.sort(np.array([s.led for s in sched.steps], dtype=int))


def bar_layouts(geometry: DomeGeometry, keep: np.ndarray, n: int) -> dict:
    """{f"uniform {floor}": the candidates (``keep[...]``) of each floor's layout} of ``n``;
    a floor whose band holds fewer than ``n`` lights is left out (and so out of the tuning:
    :func:`_tuned_floor` takes a floor only with every N)."""
    from rti_rig.core.errors import ScheduleError

    out: dict = {}
    for f in bar_floors():
        try:
            out[f"uniform {f:g}"] = keep[bar_layout(geometry, n, f)]
        except ScheduleError:
            if BAND is None:
                raise
    return out


def band_key() -> str:
    """The cache key's suffix of :data:`BAND` (nothing without one: the main tables' keys)."""
    return "" if BAND is None else f"|band {BAND[0]:g}-{BAND[1]:g}"


def band_args() -> dict[str, float]:
    """``optimal``'s band options (``plan --method optimal --min/--max-elevation-deg``)."""
    if BAND is None:
        return {}
    return {"min_elevation_deg": BAND[0], "max_elevation_deg": BAND[1]}


def band_plan(geometry: DomeGeometry, n: int, objective: str):  # type: ignore[no-untyped-def]
    """``run --adaptive --lights n --min/--max-elevation-deg`` 's plan within :data:`BAND`:
    the CLI's own :func:`adaptive_plan` on a dome (the geometry is all it reads of the rig),
    so the band's candidates and starting lights are the CLI's."""
    from types import SimpleNamespace

    from rti_rig.app.usecases.adaptive import adaptive_plan

    assert BAND is not None
    return adaptive_plan(SimpleNamespace(geometry=geometry), n, objective=objective, band=BAND)


#: `optimal`'s layouts (the slow bar to plan), which do not depend on the adaptive code:
#: ``--cache FILE`` keeps them between runs, keyed by object, draw, N and layout (the draws
#: are the same for the same seed). Scores are computed every run: the held-out set they use
#: depends on every layout compared. (Entries of the older (error, PSNR) form are still read
#: by ``benchmarks.adaptive_relight_variants`` where a cache file has them.)
_CACHE: dict[str, list[float]] = {}
_CACHE_PATH: list[Path] = []


def _cached_layout(key: str, compute) -> np.ndarray:  # type: ignore[no-untyped-def]
    """A bar's layout (indices), planned once and kept under ``layout|key``: its scores are
    computed every run, since the held-out set they use depends on every layout compared."""
    key = f"layout|{key}"
    if key not in _CACHE:
        _CACHE[key] = [float(i) for i in compute()]
    return np.asarray(_CACHE[key], dtype=int)


def common_held_out(count: int, layouts: dict[str, np.ndarray]) -> np.ndarray:
    """The candidates (of ``count``) that none of ``layouts`` took: every layout's relighting
    is scored on these, so that two layouts are compared on the same lights."""
    taken = np.concatenate([np.asarray(v, dtype=int) for v in layouts.values()])
    held = np.setdiff1d(np.arange(count), taken)
    if held.size == 0:
        raise ValueError("the compared layouts took every candidate: no light left to score on")
    return held


def _load_cache(path: Path | None) -> None:
    import json

    if path is not None and path.exists():
        _CACHE.update(json.loads(path.read_text()))


def _save_cache(path: Path | None = None) -> None:
    import json

    if path is None and _CACHE_PATH:
        path = _CACHE_PATH[0]
    if path is not None:
        path.write_text(json.dumps(_CACHE))


def adaptive_run(
    grey: np.ndarray,
    dirs: np.ndarray,
    geometry: DomeGeometry,
    n_max: int,
    until: float | None = None,
    scale: float = 1.0,
    objective: str = "normals",
    image_terms: dict[str, dict[int, float | None]] | None = None,
) -> tuple[list[int], dict[int | str, float | None], float]:
    """The chooser on pre-shot images: chosen indices, raw estimate after k images (k ≥ 4),
    and the mean decision time (s). ``objective``: as ``run --adaptive --objective``.

    ``image_terms``, if given, is filled with the stop's two terms read from the images after
    k images (``"misfit"``: the misfit bound in degrees, ``"unsolved"``: the unsolved share;
    ``planner.adaptive_until.upper_error_deg``), so that a benchmark can replay the shipped
    stop (the larger of the point estimate × the factor and the bound, plus the unsolved
    term) at any target and factor: neither term depends on the estimate's scale."""
    # as `run --adaptive --lights N` (N known); DESIGN False: light by light (for comparison)
    design = n_max if until is None and DESIGN else None
    led: np.ndarray | None = None  # with a band: the LED (index into dirs) of each candidate
    if BAND is None:
        start = START["start"](geometry, START_LIGHTS, design, objective)
    else:  # within the band: the CLI's plan (its candidates, start and design), nothing else
        if until is not None or not DESIGN or START["start"] is not dome_start:
            raise ValueError("a band is measured for `run --adaptive --lights N` as it ships")
        plan = band_plan(geometry, n_max, objective)
        dirs, led, start = plan.candidates, plan.leds, plan.start
        n_max, design = plan.max_lights, plan.design_lights
        grey = grey[led]
    chooser = AdaptiveChooser(
        dirs, start, n_max, until, scale=scale, design_lights=design, objective=objective
    )
    estimates: dict[int | str, float | None] = {}
    times = []
    for i in range(n_max + 1):
        t0 = time.perf_counter()
        c, ev = chooser.decide(i)
        if ev.get("kind") == "adaptive":
            times.append(time.perf_counter() - t0)
        if ev.get("estimated_error_deg") is not None:
            estimates[i] = float(ev["estimated_error_deg"])
            if image_terms is not None:
                # unrounded, as the stop compares them (the evidence records 4 places)
                image_terms.setdefault("misfit", {})[i] = chooser.misfit
                image_terms.setdefault("unsolved", {})[i] = chooser.unsolved
        # the upper estimate of the last decision (the stop's): what the shipped stop compared,
        # unsolved pixels included (not the point × UPPER_FACTOR alone)
        estimates["upper"] = ev.get("upper_error_deg")
        if c is None:
            break
        chooser.observe(c, dirs[c], grey[c])
    # the bound's raw mean angle and the discarded fraction after the last image (calibration)
    state = chooser.state()
    if state is not None:
        estimates["raw"] = chooser.raw_estimate(state)
        estimates["discarded"] = discarded_fraction(state)
    used = chooser.used if led is None else [int(led[c]) for c in chooser.used]
    return used, estimates, float(np.mean(times)) if times else 0.0


def _cell(bar: np.ndarray, plan: np.ndarray, higher_better: bool = False) -> str:
    c = compare(-plan, -bar) if higher_better else compare(plan, bar)
    verdict = c.verdict()
    if higher_better:
        verdict = verdict.replace("lower mean", "higher mean").replace(
            "higher mean)", "lower mean)"
        )
    return f"{bar.mean():.2f} → {plan.mean():.2f} ({c.wins}/{c.draws}, {verdict})"


def sim(draws: int, seed: int = 0, scenes: tuple[str, ...] = ()) -> tuple[dict, dict]:
    """Per scene: {(N, strategy): [errors]}, {(N, strategy): [psnr]}, and calibration pairs."""
    from benchmarks.planner_real_data import planned_leds
    from benchmarks.tradeoff import TradeoffSettings, normal_error, render_scene_data

    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    out: dict = {}
    for si, scene in enumerate(settings.scenes):
        if scenes and scene not in scenes:
            continue
        rng = np.random.default_rng([seed, si])  # a scene's draws do not depend on the others
        t0 = time.perf_counter()
        data = render_scene_data(scene, settings)
        cand = data.candidate_dirs
        lum = data.candidate_images @ REC709.astype(np.float32)
        grey = data.candidate_images.mean(axis=-1)
        err: dict = {}
        psnr: dict = {}
        fpsnr: dict = {}  # relighting of the fit.rti `rti-rig fit` writes (its HSH order)
        fbasis: dict = {}
        calib: list[tuple[int, float, float]] = []  # (N, raw estimate, measured)
        dec_t: list[float] = []
        dec_t_relight: list[float] = []
        held_counts: list[int] = []  # lights in the common held-out set, per draw and N
        for d in range(draws):
            keep = np.sort(rng.choice(len(cand), len(cand) - SIM_REMOVED, replace=False))
            sub = DomeGeometry(cand[keep], tuple(f"c{i:03d}" for i in keep))
            for n in NS:
                # one adaptive session per N: with --lights N known, the chooser plans for it;
                # and one with --objective relight (scored in the relighting table)
                used, est, dt = adaptive_run(grey[keep], cand[keep], sub, n)
                dec_t.append(dt)
                if RELIGHT:
                    used_r, _, dt_r = adaptive_run(
                        grey[keep], cand[keep], sub, n, objective="relight"
                    )
                else:  # --no-relight: the normals session stands in (its table is not a result)
                    used_r, dt_r = used, dt
                dec_t_relight.append(dt_r)
                chosen = bar_layouts(sub, keep, n)
                light = settings.preview_light_az_el_deg
                chosen["optimal"] = None
                # in index order, as the homogeneous layouts are: the same layout must give the
                # same figure to the bit (in shooting order the fit's float sums differ by
                # ~1e-7, and the sign test counts such differences as wins or losses)
                chosen["adaptive"] = keep[np.sort(used[:n])]
                chosen["adaptive relight"] = keep[np.sort(used_r[:n])]
                layouts: dict[str, np.ndarray] = {}
                for label, idx in chosen.items():
                    if idx is None:  # optimal: planned only when not in the cache

                        def plan(n=n, sub=sub, keep=keep, light=light, data=data):  # type: ignore[no-untyped-def]
                            return keep[planned_leds(data.preview, sub, n, light, **band_args())]

                        idx = _cached_layout(f"{scene}|{seed}|{d}|{n}|{label}{band_key()}", plan)
                    layouts[label] = np.asarray(idx, dtype=int)
                held = common_held_out(len(cand), layouts)
                for label, idx in layouts.items():
                    e = normal_error(data.normals, data.candidate_images[idx], cand[idx])[0]
                    mdl = relight_model(lum[idx], cand[idx], models_for(n)[-1])
                    err.setdefault((n, label), []).append(e)
                    psnr.setdefault((n, label), []).append(relight_psnr(mdl, lum[held], cand[held]))
                    basis, q = written_rti_psnr(
                        lum[idx],
                        cand[idx],
                        lum[held],
                        cand[held],
                        chosen_on=data.candidate_images[idx],
                    )
                    fpsnr.setdefault((n, label), []).append(q)
                    fbasis.setdefault((n, label), []).append(basis)
                held_counts.append(len(held))
                if "raw" in est:
                    calib.append((n, est["raw"], err[(n, "adaptive")][-1], est["discarded"]))
        until = []
        full = DomeGeometry(cand, tuple(f"c{i:03d}" for i in range(len(cand))))
        out[scene] = {
            "err": err,
            "psnr": psnr,
            "file_psnr": fpsnr,
            "file_basis": fbasis,
            "calib": calib,
            "decision_s": dec_t,
            "decision_relight_s": dec_t_relight,
            "held_out": held_counts,
            "data": (data, grey, full),
            "until": until,
        }
        _save_cache()
        print(f"{scene}: {draws} draws in {time.perf_counter() - t0:.0f} s", flush=True)
    return out, {}


def until_error_rows(results: dict, scale: float, slope: float) -> list[str]:
    """--until-error on every scene (all candidates, no draw) at each target, with the
    estimate calibrated here (scale and slope)."""
    import rti_rig.planner.adaptive as chooser_module
    from benchmarks.tradeoff import normal_error

    chooser_module.DISCARD_SLOPE = slope

    rows = []
    for scene, r in results.items():
        data, grey, full = r["data"]
        for target in TARGETS_DEG:
            used, est, _ = adaptive_run(
                grey, data.candidate_dirs, full, 60, until=target, scale=scale
            )
            idx = np.array(used)
            measured = normal_error(
                data.normals, data.candidate_images[idx], data.candidate_dirs[idx]
            )[0]
            estimate = est.get(len(used)) if est else None
            # the stop compares the upper estimate (the larger of the point × UPPER_FACTOR and
            # the misfit bound, plus the unsolved pixels' share × UNSOLVED_DEG): as recorded
            upper = est.get("upper") if estimate is not None else None
            stopped = (
                "upper estimate reached"
                if upper is not None and upper <= target
                else ("60-light cap (not claimed)")
            )
            rows.append(
                f"| {scene} | {target:g}° | {len(used)} | "
                f"{'' if estimate is None else f'{estimate:.2f}°'} | "
                f"{'' if upper is None else f'{upper:.2f}°'} | {measured:.2f}° | {stopped} |"
            )
    return rows


def _fit_factor(pairs: list[tuple], gloss: bool) -> tuple[float, float]:
    """(scale, slope) of ``log(measured / raw) = log(scale) + slope × discarded``, least squares
    (slope 0 when ``gloss`` is False: one global factor)."""
    y = np.array([np.log(m / e) for _, e, m, _ in pairs])
    if not gloss:
        return float(np.exp(y.mean())), 0.0
    x = np.array([d for *_, d in pairs])
    a = np.stack([np.ones_like(x), x], axis=1)
    (c0, c1), *_ = np.linalg.lstsq(a, y, rcond=None)
    return float(np.exp(c0)), float(c1)


def _predict(pairs: list[tuple], scale: float, slope: float) -> np.ndarray:
    return np.array([e * scale * np.exp(slope * d) for _, e, _, d in pairs])


def _calib_cells(pairs: list[tuple], scale: float, slope: float) -> list[str]:
    cells = []
    for n in NS:
        sel = [p for p in pairs if p[0] == n]
        if not sel:
            cells.append("—")
            continue
        e = _predict(sel, scale, slope)
        m = np.array([p[2] for p in sel])
        cells.append(f"{e.mean():.2f} / {m.mean():.2f} (×{np.exp(np.mean(np.log(m / e))):.2f})")
    return cells


def _log_spread(pairs: list[tuple], scale: float, slope: float) -> float:
    m = np.array([p[2] for p in pairs])
    return float(np.sqrt(np.mean(np.log(m / _predict(pairs, scale, slope)) ** 2)))


def calibrate(results: dict) -> tuple[float, float, list[str], str]:
    """The estimate's (scale, slope) fitted on every simulated scene, leave-one-scene-out
    predicted-vs-measured rows, and how far off each model is (one global factor against the
    gloss-aware one, both left out per scene)."""
    allp = [p for r in results.values() for p in r["calib"]]
    spread: dict[bool, list[float]] = {False: [], True: []}
    for scene, r in results.items():
        others = [p for s, rr in results.items() if s != scene for p in rr["calib"]]
        for g in (False, True):
            k, b = _fit_factor(others, g)
            spread[g].append(_log_spread(r["calib"], k, b))
    # the gloss-aware model is used only if it predicts left-out scenes better than one factor
    gloss = float(np.mean(spread[True])) < float(np.mean(spread[False]))
    scale, slope = _fit_factor(allp, gloss)
    rows = []
    for scene, r in results.items():
        others = [p for s, rr in results.items() if s != scene for p in rr["calib"]]
        k, b = _fit_factor(others, gloss)
        rows.append(
            f"| {scene} | {k:.2f}, {b:+.2f} | " + " | ".join(_calib_cells(r["calib"], k, b)) + " |"
        )
    summary = (
        "Typical factor between measured and estimated error (exp of the RMS log ratio, each "
        "scene predicted from the others): one global factor "
        + ", ".join(f"×{np.exp(v):.2f}" for v in spread[False])
        + "; gloss-aware "
        + ", ".join(f"×{np.exp(v):.2f}" for v in spread[True])
        + f" (scenes in order: {', '.join(results)}): "
        + ("the gloss-aware model is used." if gloss else "one global factor is used (slope 0).")
    )
    return scale, slope, rows, summary


def real(draws: int, scale: float, data: Path, seed: int = 0) -> dict:
    """The neuralrti-example dome (JPEGs linearised), paired draws, REAL_REMOVED LEDs out."""
    from benchmarks.planner_real_data import (
        DATA,
        evaluate,
        load,
        planned_leds,
        preview_leds,
        reference,
        srgb_to_linear,
    )

    dome, images, rgb8 = load(data or DATA)
    dirs = dome.directions
    ref, mask = reference(images, dirs)
    az, el = az_el_from_direction(dirs)
    previews = preview_leds(el)
    grey = np.stack([small_grey(im, 1.0) for im in images])
    rng = np.random.default_rng(seed)
    err: dict = {}
    psnr: dict = {}
    fpsnr: dict = {}  # relighting of the fit.rti `rti-rig fit` writes (its HSH order)
    fbasis: dict = {}
    calib = []
    dec_t: list[float] = []
    dec_t_relight: list[float] = []
    held_counts: list[int] = []
    for d in range(draws):
        keep = np.sort(rng.choice(len(dirs), len(dirs) - REAL_REMOVED, replace=False))
        sub = DomeGeometry(dirs[keep], tuple(dome.names[i] for i in keep))
        p = previews[d % len(previews)]
        light = (float(az[p]), float(el[p]))
        for n in NS:
            used, est, dt = adaptive_run(grey[keep], dirs[keep], sub, n, scale=scale)
            dec_t.append(dt)
            used_r, _, dt_r = adaptive_run(
                grey[keep], dirs[keep], sub, n, scale=scale, objective="relight"
            )
            dec_t_relight.append(dt_r)
            model = models_for(n)[-1]
            chosen = bar_layouts(sub, keep, n)
            chosen["optimal"] = None
            chosen["adaptive"] = keep[np.sort(used[:n])]  # index order (see sim)
            chosen["adaptive relight"] = keep[np.sort(used_r[:n])]
            layouts: dict[str, np.ndarray] = {}
            for label, idx in chosen.items():
                if idx is None:

                    def plan(n=n, keep=keep, sub=sub, p=p, light=light):  # type: ignore[no-untyped-def]
                        return keep[planned_leds(rgb8[p], sub, n, light, **band_args())]

                    idx = _cached_layout(f"real|{seed}|{d}|{n}|{label}{band_key()}", plan)
                layouts[label] = np.asarray(idx, dtype=int)
            held = common_held_out(len(dirs), layouts)
            held_counts.append(len(held))
            for label, idx in layouts.items():
                e, q, _ = evaluate(idx, images, dirs, ref, mask, model, held=held)
                err.setdefault((n, label), []).append(e)
                psnr.setdefault((n, label), []).append(q)
                # the colour stack the fit reads (the JPEGs linearised): its order choice
                rgb = srgb_to_linear(np.stack([rgb8[i] for i in idx]).astype(np.float32) / 255.0)
                basis, fq = written_rti_psnr(
                    images[idx], dirs[idx], images[held], dirs[held], mask, chosen_on=rgb
                )
                fpsnr.setdefault((n, label), []).append(fq)
                fbasis.setdefault((n, label), []).append(basis)
            if "raw" in est:
                calib.append((n, est["raw"], err[(n, "adaptive")][-1], est["discarded"]))
        _save_cache()
        print(f"real draw {d + 1}/{draws}", flush=True)
    return {
        "err": err,
        "psnr": psnr,
        "file_psnr": fpsnr,
        "file_basis": fbasis,
        "calib": calib,
        "decision_s": dec_t,
        "decision_relight_s": dec_t_relight,
        "held_out": held_counts,
    }


def _tuned_floor(scores: dict, higher_is_better: bool = False, prefix: str = "uniform") -> float:
    """The homogeneous floor with the best mean score over N (the bar, tuned with hindsight);
    ``scores`` keyed (N, f"{prefix} {floor}"), floors :func:`bar_floors`."""

    def mean(f: float) -> float:
        return float(np.mean([np.mean(scores[(n, f"{prefix} {f:g}")]) for n in NS]))

    # a floor is tuned over only where it has a layout at every N (a band may hold fewer lights
    # above a high floor than the largest N)
    draws = {n: max(len(v) for (m, _), v in scores.items() if m == n) for n in NS}
    floors = [
        f
        for f in bar_floors()
        if all(len(scores.get((n, f"{prefix} {f:g}"), ())) == draws[n] for n in NS)
    ]
    return max(floors, key=mean) if higher_is_better else min(floors, key=mean)


def _psnr_row(name: str, psnr: dict) -> str:
    """One object's row of a relighting table: the floor tuned on this PSNR with hindsight,
    then per N the tuned layout / `optimal` / adaptive (--objective relight) and the verdicts."""
    pfloor = _tuned_floor(psnr, higher_is_better=True)
    cells = []
    for n in NS:
        phom = np.array(psnr[(n, f"uniform {pfloor:g}")])
        # the relighting table scores adaptive chosen for relighting (--objective relight)
        popt, pada = np.array(psnr[(n, "optimal")]), np.array(psnr[(n, "adaptive relight")])
        pnorm = np.array(psnr[(n, "adaptive")])
        c1, c2 = compare(-pada, -phom), compare(-pada, -popt)
        cells.append(
            f"{phom.mean():.2f} / {popt.mean():.2f} / {pada.mean():.2f} "
            f"(normals objective {pnorm.mean():.2f}): vs hom "
            f"{c1.wins}/{len(pada)} {c1.verdict()}; vs opt {c2.wins}/{len(pada)} {c2.verdict()}"
        )
    return f"| {name} | {pfloor:g}° | " + " | ".join(cells) + " |"


def table(name: str, r: dict) -> tuple[str, str, str]:
    """Rows of the normals table, the relighting table (the richest basis N lights determine)
    and the written-file relighting table (fit.rti as `rti-rig fit` writes it) for one object."""
    err = r["err"]
    floor = _tuned_floor(err)
    e_cells = []
    for n in NS:
        hom = np.array(err[(n, f"uniform {floor:g}")])
        opt, ada = np.array(err[(n, "optimal")]), np.array(err[(n, "adaptive")])
        e_cells.append(
            f"{hom.mean():.2f} / {opt.mean():.2f} / {ada.mean():.2f}: vs hom "
            f"{compare(ada, hom).wins}/{len(ada)} {compare(ada, hom).verdict()}; vs opt "
            f"{compare(ada, opt).wins}/{len(ada)} {compare(ada, opt).verdict()}"
        )
    return (
        f"| {name} | {floor:g}° | " + " | ".join(e_cells) + " |",
        _psnr_row(name, r["psnr"]),
        _psnr_row(name, r["file_psnr"]),
    )


def file_bases(results: dict) -> str:
    """Which HSH orders the written fit.rti had, per N, over every layout and draw."""
    parts = []
    for n in NS:
        got: dict[str, int] = {}
        for r in results.values():
            for (m, _), bases in r["file_basis"].items():
                if m == n:
                    for b in bases:
                        got[b or "none"] = got.get(b or "none", 0) + 1
        total = sum(got.values()) or 1
        parts.append(
            f"N = {n}: " + ", ".join(f"{k} {v / total:.0%}" for k, v in sorted(got.items()))
        )
    return "; ".join(parts)


def relative_excess(r: dict) -> float:
    """A scene's share of the criterion the adaptive constants are chosen by (docs/adaptive.md):
    the sum over N of how far adaptive's mean normal error is above the tuned homogeneous
    layout's, relative to it (0 where it is not above)."""
    err = r["err"]
    floor = _tuned_floor(err)
    total = 0.0
    for n in NS:
        hom = float(np.mean(err[(n, f"uniform {floor:g}")]))
        total += max(0.0, float(np.mean(err[(n, "adaptive")])) / hom - 1.0)
    return total


def configure_planner(args: argparse.Namespace) -> None:
    """Set the planner's constants the options name (the variants measured against what ships;
    each option absent leaves its constant as it ships)."""
    import rti_rig.planner.adaptive as adaptive_planner

    if args.no_fitted_design:
        adaptive_planner.FITTED_DESIGN = False
    if args.fitted_margin is not None:
        adaptive_planner.FITTED_MARGIN = args.fitted_margin
    if args.sim_margin is not None:
        adaptive_planner.SIM_MARGIN = args.sim_margin
    if args.relight_margin is not None:
        import rti_rig.planner.adaptive_relight as adaptive_relight

        adaptive_relight.RELIGHT_MARGIN_DB = args.relight_margin
    if args.fitted_seeds:
        adaptive_planner.FITTED_SEED_FLOORS = (
            ()
            if args.fitted_seeds == "none"
            else tuple(float(x) for x in args.fitted_seeds.split(","))
        )
    if args.no_relight_fitted_design:
        import rti_rig.planner.adaptive_relight as adaptive_relight

        adaptive_relight.RELIGHT_FITTED_DESIGN = False
    if args.fitted_pixels is not None:
        import rti_rig.planner.adaptive_optimal as adaptive_optimal

        adaptive_optimal.SEARCH_PIXELS = args.fitted_pixels or None
    if args.floors:
        adaptive_planner.DESIGN_FLOORS = tuple(float(x) for x in args.floors.split(","))
    if args.default_floor is not None:
        adaptive_planner.DESIGN_DEFAULT_FLOOR = args.default_floor
    if args.relight_default_floor is not None:
        adaptive_planner.RELIGHT_DEFAULT_FLOOR = args.relight_default_floor
    if args.relight_basis is not None:  # the name the chooser calls (no constant: not shipped)
        basis = args.relight_basis
        adaptive_planner.relight_basis = lambda n_total: basis
    if args.start_above_floor is not None:
        from rti_rig.planner.adaptive_relight import OBJECTIVES

        named = tuple(x for x in args.start_above_floor.split(",") if x and x != "none")
        unknown = [x for x in named if x not in OBJECTIVES]
        if unknown:
            raise SystemExit(f"--start-above-floor: unknown objective {', '.join(unknown)}")
        adaptive_planner.START_ABOVE_FLOOR = named
    if args.no_saturation:
        import rti_rig.planner.adaptive_relight as adaptive_relight

        adaptive_relight.SATURATION = None
    if args.per_design_held_out:
        import rti_rig.planner.adaptive_relight as adaptive_relight

        adaptive_relight.SHARED_HELD_OUT = False
    if args.start != "default":  # after the default floor: a hedged start is of its layout
        from benchmarks.adaptive_reach import start_functions

        START["start"] = start_functions()[args.start]
    if args.relief_gain:
        import rti_rig.planner.adaptive_bias as bias

        bias.FIT_RELIEF_GAIN = True
    if args.clipped_censored:
        import rti_rig.planner.adaptive_bias as bias

        bias.CLIPPED_CENSORED = True
    if args.heldout_score:
        from benchmarks.adaptive_heldout import install

        install(args.heldout_score)


def build_parser() -> argparse.ArgumentParser:
    """The options of :func:`main`."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sim-draws", type=int, default=8)
    ap.add_argument("--real-draws", type=int, default=24)
    ap.add_argument("--write", action="store_true", help="write the tables into docs/adaptive.md")
    ap.add_argument(
        "--data",
        type=Path,
        default=Path("/work/shared/data/neuralrti-example"),
        help="the real acquisition (a folder with dirs.lp and its images)",
    )
    ap.add_argument("--cache", type=Path, default=None, help="keep `optimal`'s layouts here")
    ap.add_argument("--scenes", default="", help="comma-separated simulated scenes (default all)")
    ap.add_argument("--ns", default="", help="comma-separated light counts (default 6,9,12,18)")
    ap.add_argument(
        "--seed",
        type=int,
        default=0,
        help="the simulator's draws (0: those of the tables; another: fresh draws, to check a "
        "variant chosen on draws 0 on draws it was not chosen on)",
    )
    ap.add_argument(
        "--start",
        default="default",
        choices=("default", "hedge-all", "hedge-20", "hedge-10", "shared-3"),
        help="the starting lights with N known (benchmarks.adaptive_reach; default: what ships)",
    )
    ap.add_argument(
        "--start-above-floor",
        default=None,
        help="comma-separated objectives whose starting lights are matched only among the "
        "default layout's lights at or above START_FLOOR_DEG, 'none' for none "
        "(planner.adaptive.START_ABOVE_FLOOR; default what ships, relight)",
    )
    ap.add_argument(
        "--no-saturation",
        action="store_true",
        help="the relight score's renderings unclipped (planner.adaptive_relight.SATURATION "
        "None; clipped at the images' top code in what ships)",
    )
    ap.add_argument(
        "--per-design-held-out",
        action="store_true",
        help="judge each relight design on the lights it leaves out, not on those none of the "
        "designs takes (planner.adaptive_relight.SHARED_HELD_OUT False)",
    )
    ap.add_argument(
        "--floors",
        default="",
        help="comma-separated floors (°) of the designs a session chooses among "
        "(planner.adaptive.DESIGN_FLOORS; default what ships, 0,10,20,30)",
    )
    ap.add_argument(
        "--default-floor",
        type=float,
        default=None,
        help="the default design's floor (°), which also places the starting lights "
        "(planner.adaptive.DESIGN_DEFAULT_FLOOR; default what ships, 10)",
    )
    ap.add_argument(
        "--relight-default-floor",
        type=float,
        default=None,
        help="the same for --objective relight sessions "
        "(planner.adaptive.RELIGHT_DEFAULT_FLOOR; default what ships)",
    )
    ap.add_argument(
        "--relief-gain",
        action="store_true",
        help="fit the relief's depth to the captured shadows (planner.adaptive_relief; off in "
        "what ships)",
    )
    ap.add_argument(
        "--clipped-censored",
        action="store_true",
        help="the object model reads observations at white as lower bounds, not values "
        "(planner.adaptive_bias.CLIPPED_CENSORED; off in what ships)",
    )
    ap.add_argument(
        "--heldout-score",
        default=None,
        choices=(
            "select",
            "1se",
            "mean",
            "minimax",
            *(f"variant-{v}" for v in ("no-shadow", "relief2", "glossy", "matte", "smooth")),
        ),
        help="score the normals objective's designs on variants of the object model judged "
        "on held-out captured images, or on one variant (variant-NAME) "
        "(benchmarks.adaptive_heldout; not shipped)",
    )
    ap.add_argument(
        "--no-until", action="store_true", help="skip the --until-error rows (faster to iterate)"
    )
    ap.add_argument(
        "--no-fitted-design",
        action="store_true",
        help="do not offer the design of planner.adaptive_optimal (optimal on the fitted "
        "surface, the lights shot kept; offered in what ships): the floors' completions only",
    )
    ap.add_argument(
        "--fitted-pixels",
        type=int,
        default=None,
        help="search the fitted design over at most this many sampled pixels, 0 for all "
        "(planner.adaptive_optimal.SEARCH_PIXELS; default what ships, 500)",
    )
    ap.add_argument(
        "--relight-basis",
        default=None,
        choices=("ptm", "hsh1"),  # bases every N measured (6 lights or more) determines
        help="the basis --objective relight sessions score designs by (e.g. hsh1: the fit.rti "
        "`rti-rig fit` mostly writes); default: the richest basis N lights determine",
    )
    ap.add_argument(
        "--no-relight-fitted-design",
        action="store_true",
        help="do not offer the fitted relight design to --objective relight "
        "(planner.adaptive_relight_design; offered in what ships): the floors' completions only",
    )
    ap.add_argument(
        "--fitted-margin",
        type=float,
        default=None,
        help="the margin by which the fitted design must be simulated better to be taken "
        "(planner.adaptive.FITTED_MARGIN; default what ships, the floors' SIM_MARGIN)",
    )
    ap.add_argument(
        "--sim-margin",
        type=float,
        default=None,
        help="the margin by which another design must be simulated better to be taken "
        "(planner.adaptive.SIM_MARGIN; default what ships, 0.10)",
    )
    ap.add_argument(
        "--relight-margin",
        type=float,
        default=None,
        help="the dB by which another design's simulated relighting PSNR must be higher to be "
        "taken with --objective relight (planner.adaptive_relight.RELIGHT_MARGIN_DB; default "
        "what ships, 0.5)",
    )
    ap.add_argument(
        "--fitted-seeds",
        default="",
        help="comma-separated extra floors (°) whose completions also seed the fitted design's "
        "search, 'none' for none (planner.adaptive.FITTED_SEED_FLOORS; default what ships, "
        "none)",
    )
    ap.add_argument(
        "--no-relight",
        action="store_true",
        help="skip the simulator's --objective relight sessions (the relighting table is then "
        "not a result; faster to iterate on the normals objective)",
    )
    ap.add_argument(
        "--min-elevation-deg",
        type=float,
        default=None,
        help="measure within a band: adaptive as `run --adaptive --min-elevation-deg`, the bar "
        "and `optimal` as `plan --method uniform|optimal --min-elevation-deg` (the bar's floors "
        "raised to it); written to its own section (no calibration or --until-error rows)",
    )
    ap.add_argument(
        "--max-elevation-deg",
        type=float,
        default=None,
        help="the band's ceiling, as --min-elevation-deg (e.g. 45: a gilded object)",
    )
    return ap


def band_from(args: argparse.Namespace) -> tuple[float, float] | None:
    """The band the options ask for (None: neither given), checked as the CLI checks it."""
    if args.min_elevation_deg is None and args.max_elevation_deg is None:
        return None
    from rti_rig.planner.make_plan import check_elevation_band

    lo = 0.0 if args.min_elevation_deg is None else args.min_elevation_deg
    hi = 90.0 if args.max_elevation_deg is None else args.max_elevation_deg
    check_elevation_band(lo, hi)
    return None if (lo, hi) == (0.0, 90.0) else (lo, hi)  # every elevation: the main tables


def band_section(band: tuple[float, float] | None) -> str:
    """The docs section a run writes: the main tables', or the band's own."""
    if band is None:
        return "adaptive_benchmark"
    parts = ([f"min{band[0]:g}"] if band[0] > 0 else []) + (
        [f"max{band[1]:g}"] if band[1] < 90 else []
    )
    return "adaptive_band_" + "_".join(parts)


def main(argv: list[str] | None = None) -> str:
    ap = build_parser()
    args = ap.parse_args(argv)
    if args.no_relight:
        global RELIGHT
        RELIGHT = False
    global NS, BAND
    BAND = band_from(args)
    if args.sim_draws == 1 or args.sim_draws < 0 or args.real_draws == 1:
        ap.error(
            "--sim-draws and --real-draws need at least 2 (the verdicts are paired tests; "
            "--real-draws 0 skips the real acquisition, --sim-draws 0 the simulator with a band)"
        )
    if args.sim_draws == 0 and (BAND is None or not args.real_draws):
        ap.error(
            "--sim-draws 0 goes with a band and --real-draws K (the main tables' estimate is "
            "calibrated on the simulator)"
        )
    if args.ns:
        NS = tuple(int(x) for x in args.ns.split(","))
    if BAND is not None and args.start != "default":
        ap.error("a band is measured with the starting lights that ship (drop --start)")
    configure_planner(args)
    t0 = time.perf_counter()
    cache_read = args.cache is not None and args.cache.exists()
    _load_cache(args.cache)
    if args.cache is not None:
        _CACHE_PATH.append(args.cache)
    scenes = tuple(x for x in args.scenes.split(",") if x)
    results, _ = sim(args.sim_draws, seed=args.seed, scenes=scenes) if args.sim_draws else ({}, {})
    _save_cache(args.cache)
    if BAND is None:
        scale, slope, calib_rows, calib_summary = calibrate(results)
    else:  # the stop's estimate is calibrated on every elevation (the main tables), as it ships
        scale, slope, calib_rows, calib_summary = SIM_ESTIMATE_SCALE, 0.0, [], ""
    print(f"calibrated SIM_ESTIMATE_SCALE = {scale:.3f}, DISCARD_SLOPE = {slope:.3f}")
    rr = real(args.real_draws, scale, args.data) if args.real_draws else None
    _save_cache(args.cache)
    head = "| object | tuned floor | " + " | ".join(f"N = {n}" for n in NS) + " |"
    sep = "|" + "---|" * (2 + len(NS))
    e_rows, p_rows, f_rows = [], [], []
    for scene, r in results.items():
        a, b, c = table(scene, r)
        e_rows.append(a)
        p_rows.append(b)
        f_rows.append(c)
    real_calib = []
    if rr is not None:
        a, b, c = table("neuralrti-example (real)", rr)
        e_rows.append(a)
        p_rows.append(b)
        f_rows.append(c)
        cells = _calib_cells(rr["calib"], scale, slope)
        real_calib.append(
            f"| neuralrti-example (real) | {scale:.2f}, {slope:+.2f} | " + " | ".join(cells) + " |"
        )
    excess = {scene: relative_excess(r) for scene, r in results.items()}
    excess_line = (
        f"Σ relative excess over the tuned layout (normals, simulator): {sum(excess.values()):.3f}"
        " (" + ", ".join(f"{k} {v:.3f}" for k, v in excess.items()) + ")."
    )
    print(excess_line, flush=True)
    until_rows = [] if args.no_until or BAND else until_error_rows(results, scale, slope)
    timed = results or {"real": rr}  # the simulator's sessions; the real dome's without it
    dec = np.concatenate([r["decision_s"] for r in timed.values()])
    dec_r = np.concatenate([r["decision_relight_s"] for r in timed.values()])
    held_sim = np.concatenate([r["held_out"] for r in results.values()]) if results else []
    held_real = rr["held_out"] if rr else []

    def _span(counts) -> str:  # type: ignore[no-untyped-def]
        return f"{min(counts)}–{max(counts)}, median {np.median(counts):g}" if len(counts) else "—"

    held_line = (
        "Relighting is scored, in each draw and N, on the lights none of the compared layouts "
        "took (the uniform floors, `optimal` and both adaptive sessions), the same for all of "
        f"them: {_span(held_sim)} held-out lights on the simulator, {_span(held_real)} on the "
        "real dome (its out-of-service LEDs among them). Before 2026-11-24 each layout was "
        "scored on the lights it did not take."
    )
    parts = (
        [
            f"Command: `python -m benchmarks.adaptive --sim-draws {args.sim_draws} "
            f"--real-draws {args.real_draws}"
            + (f" --scenes {args.scenes}" if args.scenes else "")
            + (f" --ns {args.ns}" if args.ns else "")
            + (f" --seed {args.seed}" if args.seed else "")
            + (" --no-until" if args.no_until else "")
            + (f" --start {args.start}" if args.start != "default" else "")
            + (f" --floors {args.floors}" if args.floors else "")
            + (f" --default-floor {args.default_floor:g}" if args.default_floor is not None else "")
            + (
                f" --relight-default-floor {args.relight_default_floor:g}"
                if args.relight_default_floor is not None
                else ""
            )
            + (" --relief-gain" if args.relief_gain else "")
            + (" --clipped-censored" if args.clipped_censored else "")
            + (f" --heldout-score {args.heldout_score}" if args.heldout_score else "")
            + (" --no-fitted-design" if args.no_fitted_design else "")
            + (f" --fitted-pixels {args.fitted_pixels}" if args.fitted_pixels is not None else "")
            + (f" --relight-basis {args.relight_basis}" if args.relight_basis else "")
            + (" --no-relight-fitted-design" if args.no_relight_fitted_design else "")
            + (f" --fitted-margin {args.fitted_margin:g}" if args.fitted_margin is not None else "")
            + (f" --fitted-seeds {args.fitted_seeds}" if args.fitted_seeds else "")
            + (f" --sim-margin {args.sim_margin:g}" if args.sim_margin is not None else "")
            + (
                f" --relight-margin {args.relight_margin:g}"
                if args.relight_margin is not None
                else ""
            )
            + (" --no-relight" if args.no_relight else "")
            + (
                f" --min-elevation-deg {args.min_elevation_deg:g}"
                if args.min_elevation_deg is not None
                else ""
            )
            + (
                f" --max-elevation-deg {args.max_elevation_deg:g}"
                if args.max_elevation_deg is not None
                else ""
            )
            + (" --cache FILE" if args.cache else "")
            + f" --write` ({time.perf_counter() - t0:.0f} s"
            + (
                "; `optimal`'s layouts read from FILE, planned by an earlier run of the same "
                "command on the same draws (valid only while that planner is unchanged); every "
                "score computed in this run"
                if cache_read
                else "; every score computed in this run"
            )
            + f"; load average {os.getloadavg()[0]:.1f} at the end). "
            + machine_line(),
            "",
            (
                f"Simulator: {args.sim_draws} paired draws per scene, {SIM_REMOVED} of 240 "
                "candidate lights out of service per draw; real dome: "
                if results
                else "Real dome only: "
            )
            + f"{args.real_draws} draws, {REAL_REMOVED} of 72 LEDs out. Cells: mean of the "
            "hindsight-tuned homogeneous layout / `optimal` / adaptive, then adaptive's paired "
            "verdict against each (draws won, `benchmarks.paired`: win/loss only when the "
            "bootstrap interval and the sign test agree)." + band_line(),
            "",
            "Normal error (°):",
            "",
            head,
            sep,
            *e_rows,
            "",
            *([excess_line, ""] if results else []),
        ],
        [
            *(
                [
                    "**`--no-relight`: no `--objective relight` session was run on the "
                    "simulator**: in its rows of the two relighting tables below, adaptive (the "
                    "cell and the bracket alike) is the normals-objective session of the table "
                    "above.",
                    "",
                ]
                if args.no_relight
                else []
            ),
            "Relighting PSNR (dB; floor tuned on PSNR; adaptive here is `run --adaptive --lights N "
            "--objective relight`, each cell also giving the PSNR of the normals-objective "
            "sessions of the table above; `optimal` is the normals objective's plan, as above; a "
            "'lower mean' verdict here means a lower *negative* PSNR, i.e. a higher PSNR for "
            "adaptive). " + held_line,
            "",
            head,
            sep,
            *p_rows,
            "",
            "Relighting PSNR of the file a user opens (dB): fit.rti as `rti-rig fit` writes it, "
            "its HSH order chosen on held-out lights (`rti_rig/app/usecases/fit_rti_order.py`), "
            "not the richest basis the lights determine; the same held-out lights, layouts and "
            "sessions as the table above, the floor tuned on this PSNR. Orders written: "
            + file_bases({**results, **({"real": rr} if rr is not None else {})})
            + ".",
            "",
            head,
            sep,
            *f_rows,
            "",
        ],
        [
            f"Error estimate (the stopping rule's): the *simulated* error — the robust fit run on "
            "observations simulated from this object's model (gloss, cast shadows, noise; "
            f"planner/adaptive_bias.py) under the lights so far — × {scale:.3f} × "
            f"exp({slope:.2f} × the fraction of observations the fit discarded) (least squares "
            "of log measured/simulated over all simulated scenes, draws and N, fitted by this "
            f"run; the shipped `SIM_ESTIMATE_SCALE` in planner/adaptive.py is "
            f"{SIM_ESTIMATE_SCALE:.3f}). Cells: mean predicted / mean measured "
            "(geometric-mean ratio measured/predicted); simulator rows use the factors fitted on "
            "the *other* scenes; the real row uses the simulator's (never fitted on it; measured "
            "= against the all-72-light fit, which is itself not the truth). " + calib_summary,
            "",
            "| object | scale, slope used | " + " | ".join(f"N = {n}" for n in NS) + " |",
            "|" + "---|" * (2 + len(NS)),
            *calib_rows,
            *real_calib,
            "",
            "`--until-error` on each simulated scene (all 240 candidates, capped at 60 lights):",
            "",
            "| scene | target | lights used | estimate at stop | upper estimate (the stop's: "
            f"×{UPPER_FACTOR:g} or the misfit bound, plus unsolved pixels × 90°) | measured | "
            "why it stopped |",
            "|---|---|---|---|---|---|---|",
            *until_rows,
            "",
        ],
        [
            f"Decision time on the {'simulator' if results else 'real dome'}'s "
            f"{'96-px' if results else 'small'} images: "
            f"median {np.median(dec) * 1e3:.0f} ms per decision with the normals objective, "
            + (
                "no `--objective relight` session run"
                if args.no_relight and results
                else f"{np.median(dec_r) * 1e3:.0f} ms with `--objective relight`"
            )
            + " (means per session, medians over sessions; fit + choice; for "
            "24-MP images see `benchmarks.adaptive_time`).",
        ],
    )
    if BAND is not None:  # the band's own section: its tables (the estimate is calibrated and
        # --until-error measured on every elevation, in the main tables)
        parts = (parts[0], parts[1], parts[3])
    md = "\n".join(line for part in parts for line in part)
    print(md)
    if args.write:
        write_section(band_section(BAND) + ("" if results else "_real"), md, DOC)
    return md


def band_line() -> str:
    """What the band changes in the tables (nothing without one)."""
    if BAND is None:
        return ""
    floors = "/".join(f"{f:g}°" for f in bar_floors())
    return (
        f" **Every strategy keeps to {BAND[0]:g}°–{BAND[1]:g}° elevation**: adaptive is "
        "`run --adaptive --lights N` with the band (its candidates and starting lights from the "
        "CLI's `adaptive_plan`), `optimal` is `plan --method optimal` with the band, and the "
        f"bar is tuned over the homogeneous layouts above {floors} within it (`plan --method "
        "uniform --min-elevation-deg FLOOR --max-elevation-deg CEILING`: 0°/10°/20°/30° raised "
        "to the band's floor, each kept once, a floor at or above the ceiling dropped, and a "
        "floor whose band holds fewer lights than an N left out of the tuning). Relighting is "
        "still scored on every held-out light, those outside the band included (a user relights "
        "there too, as `plan --objective relight` scores a ceiling)."
    )


if __name__ == "__main__":
    main(sys.argv[1:])
