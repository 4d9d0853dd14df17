"""An elevation ceiling: what keeping lights away from the camera axis does, real and simulated.

On a level glossy object a light near the camera axis sends its mirror highlight straight into
the camera, and robust photometric stereo keeps the highlight's weaker tails. Both the real
dome's evidence (its six high LEDs towards the gilding's mirror direction raised the error by
1.6–4.1° in any 12-light subset, ``benchmarks.real_led_effects``) and the simulator's
hindsight oracle (``benchmarks.planner_sim_oracle``: its layouts on the varnished painting and
the polished coin put most lights low) point the same way, so a ceiling
(``rti-rig plan --max-elevation-deg``) is measured here for the homogeneous layout and the
planner, in the paired designs of ``benchmarks.planner_real_draws`` (real dome, :data:`REAL_DRAWS`
draws, 8 LEDs out of service, previews of 40–62° elevation) and
``benchmarks.planner_sim_draws`` (five scenes, 8 draws, 24 of 240 candidates out of service).

:data:`CEILING` (60°: the mirror direction of normals tilted up to 15°) was set before any
run; :data:`SENSITIVITY` gives the planner at 50° and 70° too, to show how much hangs on it.
The bar is the homogeneous layout with its floor tuned with hindsight, as everywhere.

Run: ``python -m benchmarks.planner_ceiling`` (``sim`` or ``real`` for one part: 18 and 20
minutes when run side by side on 2 cores; each writes its section of docs/research/planner.md).
``--seed K`` (K ≠ 0) draws fresh subsets and only prints its tables: the checks of the
committed ones that docs/research/planner.md quotes. The real part needs
``../shared/data/neuralrti-example``.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from benchmarks.planner_real_data import (
    DATA,
    DOC,
    NS,
    evaluate,
    load,
    planned_leds,
    preview_leds,
    reference,
)
from benchmarks.planner_sim_draws import (
    COUNTS,
    DRAWS,
    REMOVED,
    cell,
    paired_draws,
    table_head,
)
from benchmarks.report import write_section
from benchmarks.tradeoff import TradeoffSettings, normal_error, render_scene_data
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.objectives import models_for
from rti_rig.planner.uniform import select_uniform_leds

CEILING = 60.0
SENSITIVITY = (50.0, 70.0)
FLOORS = (0.0, 10.0, 20.0, 30.0)
#: Floors tried for the homogeneous layout under the ceiling (tuned with hindsight as well).
BAND_FLOORS = (0.0, 10.0, 20.0)
REAL_DRAWS = 48
REAL_REMOVED = 8
#: Seed of the committed tables' draws; other seeds (``--seed``) give fresh draws and only print.
SEED = 0
#: Seed of the bootstrap intervals, the same whatever the draws' seed.
BOOTSTRAP_SEED = 0

#: (label, material, ceiling) of the planned strategies.
PLANNED: tuple[tuple[str, str, float], ...] = (
    ("optimal", "auto", 90.0),
    (f"optimal ≤{CEILING:g}°", "auto", CEILING),
    *((f"optimal ≤{c:g}°", "auto", c) for c in SENSITIVITY),
    ("optimal glossy", "glossy", 90.0),
    (f"optimal glossy ≤{CEILING:g}°", "glossy", CEILING),
)


def strategies(
    geometry: DomeGeometry,
    n: int,
    plan: Callable[[DomeGeometry, int, str, float], NDArray[np.intp]],
) -> dict[str, NDArray[np.intp]]:
    """Every strategy's layout (indices into ``geometry``) for one draw: homogeneous at each
    floor, homogeneous under the ceiling at each band floor, and the planned ones."""
    out = {f"uniform {f:g}": select_uniform_leds(geometry, n, f) for f in FLOORS}
    for f in BAND_FLOORS:
        out[f"band {f:g}"] = select_uniform_leds(geometry, n, f, max_elevation_deg=CEILING)
    for label, material, ceiling in PLANNED:
        out[label] = plan(geometry, n, material, ceiling)
    return out


def tuned(
    err: dict[tuple[int, str], list[float]],
    prefix: str,
    floors: Sequence[float],
    counts: Sequence[int] | None = None,
) -> str:
    """The label of the hindsight floor: lowest mean over the draws of ``counts`` (default:
    every N)."""
    counts = counts or sorted({n for n, _ in err})
    return min(
        (f"{prefix} {f:g}" for f in floors),
        key=lambda lab: float(np.mean([np.mean(err[(n, lab)]) for n in counts])),
    )


def add_bars(
    err: dict[tuple[int, str], list[float]],
    counts: Sequence[int],
    per_n: bool,
    *also: dict[tuple[int, str], list[float]],
) -> dict[str, str]:
    """Add the tuned homogeneous layouts to ``err`` as ``bar`` (floor of :data:`FLOORS`) and
    ``band`` (under the ceiling, floor of :data:`BAND_FLOORS`), tuned per N (as the real dome's
    benchmarks do) or once over every N (as the simulator's do); ``also`` (e.g. the same
    layouts' relighting PSNR) gets the same layouts under the same keys. Returns their display
    names."""
    names = {}
    for key, prefix, floors, what in (
        ("bar", "uniform", FLOORS, "homogeneous"),
        ("band", "band", BAND_FLOORS, f"homogeneous ≤{CEILING:g}°"),
    ):
        chosen = {n: tuned(err, prefix, floors, [n] if per_n else counts) for n in counts}
        for n in counts:
            for table in (err, *also):
                table[(n, key)] = table[(n, chosen[n])]
        shown = (
            "/".join(chosen[n].split()[-1] for n in counts)
            if per_n
            else chosen[counts[0]].split()[-1]
        )
        names[key] = f"{what}, tuned floor{' per N' if per_n else ''} ({shown}°)"
    return names


def sim_rows(seed: int = SEED) -> list[str]:
    """Table rows of the simulator part: every scene's paired draws (``seed``), with the bars
    tuned once over every N, as ``benchmarks.planner_sim_draws`` does."""
    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    rows = []
    for scene in settings.scenes:
        data = render_scene_data(scene, settings)
        cand = data.candidate_dirs
        light = settings.preview_light_az_el_deg
        rng = np.random.default_rng(seed)
        err: dict[tuple[int, str], list[float]] = {}
        for n, keep, sub in paired_draws(cand, COUNTS, DRAWS, REMOVED, rng):

            def plan(
                g: DomeGeometry, k: int, material: str, ceiling: float, data=data, light=light
            ) -> NDArray:
                return planned_leds(
                    data.preview, g, k, light, material=material, max_elevation_deg=ceiling
                )

            for label, idx in strategies(sub, n, plan).items():
                sel = keep[idx]
                err.setdefault((n, label), []).append(
                    normal_error(data.normals, data.candidate_images[sel], cand[sel])[0]
                )
        rows.extend(_rows(scene, err, add_bars(err, COUNTS, per_n=False), COUNTS))
        print(f"{scene}: done")
        sys.stdout.flush()
    return rows


def real_rows(seed: int = SEED) -> tuple[list[str], list[str]]:
    """Table rows of the real-dome part (``seed``'s draws, bars tuned per N, as
    ``benchmarks.planner_real_draws`` does) and the relighting PSNR rows of the same layouts."""
    dome, images, rgb8 = load(DATA)
    dirs = dome.directions
    ref, mask = reference(images, dirs)
    az, el = az_el_from_direction(dirs)
    previews = preview_leds(el)
    rng = np.random.default_rng(seed)
    err: dict[tuple[int, str], list[float]] = {}
    psnr: dict[tuple[int, str], list[float]] = {}
    for n in NS:
        model = models_for(n)[-1]
        for d in range(REAL_DRAWS):
            keep = np.sort(rng.choice(len(dirs), len(dirs) - REAL_REMOVED, replace=False))
            sub = DomeGeometry(dirs[keep], tuple(dome.names[i] for i in keep))
            p = previews[d % len(previews)]
            light = (float(az[p]), float(el[p]))

            def plan(
                g: DomeGeometry, k: int, material: str, ceiling: float, p=p, light=light
            ) -> NDArray:
                return planned_leds(
                    rgb8[p], g, k, light, material=material, max_elevation_deg=ceiling
                )

            for label, idx in strategies(sub, n, plan).items():
                e, q, _ = evaluate(keep[idx], images, dirs, ref, mask, model)
                err.setdefault((n, label), []).append(e)
                psnr.setdefault((n, label), []).append(q)
        print(f"real dome, N = {n}: done")
        sys.stdout.flush()
    names = add_bars(err, NS, True, psnr)  # the relighting of the same layouts
    rows = _rows("real dome (icon)", err, names, NS)
    relit = [
        f"| {names.get(label, label)} | "
        + " | ".join(f"{np.mean(psnr[(n, label)]):.2f}" for n in NS)
        + " |"
        for label in (
            "bar",
            "band",
            "optimal",
            f"optimal ≤{CEILING:g}°",
            "optimal glossy",
            f"optimal glossy ≤{CEILING:g}°",
        )
    ]
    return rows, relit


def _rows(
    what: str,
    err: dict[tuple[int, str], list[float]],
    names: dict[str, str],
    counts: Sequence[int],
) -> list[str]:
    """Table rows: each strategy against the tuned homogeneous layout (``bar``), the planner
    under the ceiling against the homogeneous layout under it (``band``), and the ceiling's own
    effect on the planner (and on the declared-glossy planner)."""
    pairs = [
        ("bar", "band"),
        ("bar", "optimal"),
        ("bar", f"optimal ≤{CEILING:g}°"),
        *(("bar", f"optimal ≤{c:g}°") for c in SENSITIVITY),
        ("bar", f"optimal glossy ≤{CEILING:g}°"),
        ("band", f"optimal ≤{CEILING:g}°"),
        ("optimal", f"optimal ≤{CEILING:g}°"),
        ("optimal glossy", f"optimal glossy ≤{CEILING:g}°"),
    ]
    rows = []
    for first, second in pairs:
        cells = " | ".join(
            cell(np.array(err[(n, first)]), np.array(err[(n, second)]), BOOTSTRAP_SEED)
            for n in counts
        )
        shown = f"{names.get(first, first)} → {names.get(second, second)}"
        rows.append(f"| {what} | {shown} | {cells} |")
    return rows


def parts_arg(text: str) -> tuple[str, ...]:
    """The command line's parts, refused unless each is ``sim`` or ``real`` (a typo would
    otherwise run nothing and succeed)."""
    parts = tuple(p.strip() for p in text.split(","))
    unknown = [p for p in parts if p not in ("sim", "real")]
    if unknown or not parts:
        raise argparse.ArgumentTypeError(f"unknown part {unknown}: give sim, real or sim,real")
    return parts


def main(parts: Sequence[str] = ("sim", "real"), seed: int = SEED) -> str:
    """Run the parts asked for; each writes its own section of docs/research/planner.md, so the
    two can run at the same time (``python -m benchmarks.planner_ceiling sim`` / ``real``). With
    another ``seed`` than :data:`SEED` the draws are fresh and the tables are printed, not
    written: the docs quote such runs as checks of the committed tables."""
    head = (
        f"Ceiling {CEILING:g}° (set before any run), {SENSITIVITY[0]:g}° and {SENSITIVITY[1]:g}° "
        "for the planner's sensitivity. Cells: mean normal error (°) of the first strategy → "
        "of the second (draws the second won, verdict: bootstrap interval and sign test). The "
        "homogeneous bar's floor (0/10/20/30°) and the floor of the homogeneous layout under "
        "the ceiling (0/10/20°) are tuned with hindsight: per scene on the simulator, per N "
        "on the real dome (as the other benchmarks of each do)."
    )
    flag = "" if seed == SEED else f" --seed {seed}"
    out = []
    if "sim" in parts:
        t0 = time.perf_counter()
        sim = sim_rows(seed)
        md = "\n".join(
            [
                f"Command: `python -m benchmarks.planner_ceiling sim{flag}` (total "
                f"{time.perf_counter() - t0:.0f} s, seed {seed}). Simulator: {DRAWS} draws per "
                f"N, {REMOVED} of 240 candidates out of service. {head}",
                "",
                *table_head("scene", "comparison"),
                *sim,
            ]
        )
        if seed == SEED:
            write_section("planner_ceiling_sim", md, DOC)
        out.append(md)
    if "real" in parts:
        t0 = time.perf_counter()
        real, relit = real_rows(seed)
        md = "\n".join(
            [
                f"Command: `python -m benchmarks.planner_ceiling real{flag}` (total "
                f"{time.perf_counter() - t0:.0f} s, seed {seed}). Real dome (neuralrti-example, "
                f"{REAL_DRAWS} draws per N, {REAL_REMOVED} LEDs out of service, previews lit "
                f"from 40–62°). {head}",
                "",
                "| object | comparison | " + " | ".join(f"N = {n}" for n in NS) + " |",
                "|---|---|" + "---|" * len(NS),
                *real,
                "",
                "Relighting PSNR (dB, mean over the draws; the richest basis the light count "
                "determines, relit to the dome's other LEDs, high ones included):",
                "",
                "| layout | " + " | ".join(f"N = {n}" for n in NS) + " |",
                "|---|" + "---|" * len(NS),
                *relit,
            ]
        )
        if seed == SEED:
            write_section("planner_ceiling_real", md, DOC)
        out.append(md)
    text = "\n\n".join(out)
    print(text)
    return text


if __name__ == "__main__":
    cli = argparse.ArgumentParser(prog="python -m benchmarks.planner_ceiling")
    cli.add_argument(
        "parts",
        nargs="?",
        default="sim,real",
        type=parts_arg,
        help="sim, real or sim,real",
    )
    cli.add_argument("--seed", type=int, default=SEED, help="draws' seed (not 0: print only)")
    cli.add_argument(
        "--write", action="store_true", help="write the tables into docs/ (else print only)"
    )
    args = cli.parse_args()
    main(args.parts, args.seed)
