"""Did making `optimal` fast make its plans worse? A small paired check to run before and after.

The paired design of ``benchmarks.planner_sim_instances`` (``DRAWS`` draws per N with
``REMOVED`` of the 240 candidates out of service; every strategy plans on the same remaining
ones, preview lit from az/el 45°/50°) on a small setting: per scene and N, the mean normal error
of robust photometric stereo against the scene's true normals for the homogeneous layout at each
floor and for ``optimal`` (from the preview), the planner's own expected error (its objective) and
its planning time. Printed, not written: the point is the before/after comparison of one
planner change (docs/adaptive.md, "adaptive_time", cites the figures).

Run: ``python -m benchmarks.planner_speed_guard [--draws 3] [--counts 6,12,30,50]
[--scenes painting,coin,...]``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

from benchmarks.planner_sim_draws import FLOORS, paired_draws
from benchmarks.tradeoff import TradeoffSettings, normal_error, render_scene_data
from rti_rig.planner.make_plan import plan_with_report
from rti_rig.planner.uniform import select_uniform_leds

REMOVED = 24


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--draws", type=int, default=3)
    ap.add_argument("--counts", default="6,12,30,50")
    ap.add_argument("--scenes", default="painting,coin,tilted,industrial,tablet")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    counts = tuple(int(c) for c in args.counts.split(","))
    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50, seed=0)
    lines = [
        "| scene | N | best uniform floor: mean ° | `optimal` mean ° | optimal − uniform ° "
        "| `optimal` expected ° (objective) | plan s (median) |",
        "|---|---|---|---|---|---|---|",
    ]
    t_all = time.perf_counter()
    for scene in args.scenes.split(","):
        data = render_scene_data(scene, settings)
        cand = data.candidate_dirs
        rng = np.random.default_rng(args.seed)
        err: dict[tuple[int, str], list[float]] = {}
        expected: dict[int, list[float]] = {}
        seconds: dict[int, list[float]] = {}
        for n, keep, sub in paired_draws(cand, counts, args.draws, REMOVED, rng):
            chosen = {f"uniform {f:g}": keep[select_uniform_leds(sub, n, f)] for f in FLOORS}
            t0 = time.perf_counter()
            sched, report = plan_with_report(
                data.preview, sub, n, "optimal", "normals", settings.preview_light_az_el_deg
            )
            seconds.setdefault(n, []).append(time.perf_counter() - t0)
            expected.setdefault(n, []).append(report.expected["optimal"])
            chosen["optimal"] = keep[np.array([s.led for s in sched.steps])]
            for label, idx in chosen.items():
                err.setdefault((n, label), []).append(
                    normal_error(data.normals, data.candidate_images[idx], cand[idx])[0]
                )
        for n in counts:
            best = min(FLOORS, key=lambda f, n=n: float(np.mean(err[(n, f"uniform {f:g}")])))
            uni = float(np.mean(err[(n, f"uniform {best:g}")]))
            opt = float(np.mean(err[(n, "optimal")]))
            lines.append(
                f"| {scene} | {n} | {best:g}°: {uni:.3f} | {opt:.3f} | {opt - uni:+.3f} | "
                f"{np.mean(expected[n]):.4f} | {statistics.median(seconds[n]):.2f} |"
            )
            print(lines[-1], flush=True)
    lines.append("")
    lines.append(
        f"{args.draws} paired draws per N, {REMOVED} of 240 candidates out of service, scene "
        f"seed 0; total {time.perf_counter() - t_all:.0f} s."
    )
    md = "\n".join(lines)
    print(md)
    return md


if __name__ == "__main__":
    main(sys.argv[1:])
