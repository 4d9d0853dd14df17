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
  else ``default``): both designs stay exactly reachable, the first decision is on 3 images.

Run: ``python -m benchmarks.adaptive_reach [--draws K] [--scenes a,b] [--write]`` (about
1–2 min on 2 idle cores; ``--write`` puts the table into docs/adaptive.md).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from benchmarks.report import machine_line, write_section
from rti_rig.app.usecases.adaptive import dome_start
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner import adaptive
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


def shared_three_start(geometry: DomeGeometry, k: int, n_total: int | None) -> list[int]:
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


def start_functions() -> dict:  # type: ignore[type-arg]
    others = tuple(f for f in FLOORS if f != adaptive.DESIGN_DEFAULT_FLOOR)
    return {
        "default": dome_start,
        "hedge-all": lambda g, k, n: hedged_start(g, k, n, others),
        "hedge-20": lambda g, k, n: hedged_start(g, k, n, (20.0,)),
        "shared-3": shared_three_start,
    }


def reach(draws: int, scenes: tuple[str, ...] = (), seed: int = 0) -> list[str]:
    """Table rows: per scene and N, the tuned bar and, per start, each floor's completion (mean
    over draws) and the oracle."""
    from benchmarks.tradeoff import TradeoffSettings, normal_error, render_scene_data

    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    starts = start_functions()
    rows = []
    for si, scene in enumerate(settings.scenes):
        if scenes and scene not in scenes:
            continue
        rng = np.random.default_rng([seed, si])  # the draws of benchmarks.adaptive
        data = render_scene_data(scene, settings)
        cand = data.candidate_dirs

        def err(idx: NDArray[np.intp], data=data, cand=cand) -> float:  # type: ignore[no-untyped-def]
            idx = np.sort(idx)  # index order, as benchmarks.adaptive scores every layout
            return normal_error(data.normals, data.candidate_images[idx], cand[idx])[0]

        res: dict[tuple[int, str], list[float]] = {}
        for _ in range(draws):
            keep = np.sort(rng.choice(len(cand), len(cand) - SIM_REMOVED, replace=False))
            sub = DomeGeometry(cand[keep], tuple(f"c{i:03d}" for i in keep))
            for n in NS:
                for f in FLOORS:
                    res.setdefault((n, f"hom {f:g}"), []).append(
                        err(keep[select_uniform_leds(sub, n, f)])
                    )
                for name, fn in starts.items():
                    st = fn(sub, adaptive.START_LIGHTS, n)  # first decision after len(st)
                    avail = np.ones(len(keep), dtype=bool)
                    avail[st] = False
                    for f in FLOORS:
                        comp = adaptive.homogeneous_completion(
                            cand[keep], avail, cand[keep][st], n, f
                        )
                        assert comp is not None
                        res.setdefault((n, f"{name} {f:g}"), []).append(err(keep[np.r_[st, comp]]))
        tuned = min(FLOORS, key=lambda f: np.mean([np.mean(res[(n, f"hom {f:g}")]) for n in NS]))
        for n in NS:
            bar = float(np.mean(res[(n, f"hom {tuned:g}")]))
            cells = []
            for name in starts:
                per = np.array([res[(n, f"{name} {f:g}")] for f in FLOORS])  # (F, draws)
                oracle = float(per.min(axis=0).mean())
                fixed = " ".join(f"{v:.3g}" for v in per.mean(axis=1))
                flag = " **above the bar**" if oracle > bar * (1 + 1e-9) else ""
                cells.append(f"{fixed}; oracle {oracle:.3g}{flag}")
            rows.append(f"| {scene} | {n} | {tuned:g}°: {bar:.3g} | " + " | ".join(cells) + " |")
        print(f"{scene} done", flush=True)
    return rows


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--draws", type=int, default=8)
    ap.add_argument("--scenes", default="", help="comma-separated simulated scenes (default all)")
    ap.add_argument("--write", action="store_true", help="write the table into docs/adaptive.md")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = reach(args.draws, tuple(x for x in args.scenes.split(",") if x))
    floors = "/".join(f"{f:g}°" for f in FLOORS)
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.adaptive_reach --draws {args.draws} --write` "
            f"({time.perf_counter() - t0:.0f} s; load average {os.getloadavg()[0]:.1f} at the "
            "end). " + machine_line(),
            "",
            f"Simulator, {args.draws} paired draws (the draws of `benchmarks.adaptive`). Per "
            f"start: the true mean normal error (°) of the design completed above {floors} when "
            "decided at the first decision (after the starting lights: 4 images, 3 for "
            "`shared-3` where it applies), then the oracle (the best floor per draw: a "
            "perfect model). The bar: the hindsight-tuned homogeneous layout.",
            "",
            "| scene | N | bar | start `default` (ships) | start `hedge-all` | start `hedge-20` | "
            "start `shared-3` |",
            "|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section("adaptive_reach", md, DOC)
    return md


if __name__ == "__main__":
    main(sys.argv[1:])
