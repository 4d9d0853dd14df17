"""How far the planner is from the best layouts on the simulator: a hindsight bound per scene.

``benchmarks.planner_sim_draws`` says where the planner beats a tuned homogeneous layout and
where it loses. It cannot say whether the losses are the planner's fault or the scene's: maybe
no layout does much better than an even one there. This benchmark answers that with an oracle
that sees what no planner can, the scene's true normals. Starting from the better of the tuned
homogeneous layout and the planner's (on its own cost), it swaps single lights (all 240
candidates, no draws) to lower the measured error of robust photometric stereo against the
truth: :data:`SWEEPS` sweeps, every :data:`STRIDE`-th candidate per sweep, scored on every other
pixel of every other row (:func:`benchmarks.planner_real_data.hindsight_exchange`).

Its layouts are chosen on the very noisy images they are scored on, which flatters them, so
every layout is scored again on a second shot of the same lights with fresh sensor noise
(:data:`FRESH_NOISE_SEED`); the table gives both. The oracle is a near-bound, not a bound: a
greedy search from one start.

Run: ``python -m benchmarks.planner_sim_oracle`` (53 minutes in the committed run, sharing 2
cores with two other benchmarks; writes its section of docs/research/planner.md).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterable

import numpy as np
from numpy.typing import NDArray

from benchmarks.planner_real_data import DOC, hindsight_exchange, planned_leds
from benchmarks.planner_sim_draws import COUNTS, FLOORS
from benchmarks.report import positional_args, write_section
from benchmarks.tradeoff import (
    SceneData,
    TradeoffSettings,
    normal_error,
    render_scene_data,
    scene_camera,
)
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.uniform import select_uniform_leds

SWEEPS = 2
STRIDE = 2
#: Pixels the oracle scores: every ``PIXEL_STEP``-th of every ``PIXEL_STEP``-th row.
PIXEL_STEP = 2
FRESH_NOISE_SEED = 1000
#: Lights below this elevation are counted in the table (where the layouts differ most).
LOW_DEG = 30.0


def true_error_cost(data: SceneData, step: int = PIXEL_STEP) -> Callable[[Iterable[int]], float]:
    """Mean angle (°) of robust photometric stereo on a layout to the true normals, on a
    regular subsample of the pixels (the oracle's cost)."""
    truth = data.normals[::step, ::step]
    images = data.candidate_images[:, ::step, ::step]

    def cost(sel: Iterable[int]) -> float:
        idx = np.asarray(list(sel), dtype=np.intp)
        return normal_error(truth, images[idx], data.candidate_dirs[idx])[0]

    return cost


def fresh_shots(
    scene: str, settings: TradeoffSettings, dirs: NDArray[np.float64], lights: Iterable[int]
) -> dict[int, NDArray[np.float32]]:
    """A second noisy image of each candidate in ``lights`` (the same scene and camera)."""
    _, shoot = scene_camera(scene, settings)
    rng = np.random.default_rng(FRESH_NOISE_SEED)
    return {int(k): shoot(dirs[k], rng) for k in sorted(set(int(k) for k in lights))}


def scene_rows(scene: str, settings: TradeoffSettings) -> list[str]:
    """One table row per light count for ``scene``."""
    data = render_scene_data(scene, settings)
    dirs = data.candidate_dirs
    dome = DomeGeometry(dirs, tuple(f"c{i:03d}" for i in range(len(dirs))))
    _, el = az_el_from_direction(dirs)

    def measured(idx: NDArray[np.intp]) -> float:
        return normal_error(data.normals, data.candidate_images[idx], dirs[idx])[0]

    uniform = {(n, f): select_uniform_leds(dome, n, f) for n in COUNTS for f in FLOORS}
    floor = min(FLOORS, key=lambda f: float(np.mean([measured(uniform[(n, f)]) for n in COUNTS])))
    cost = true_error_cost(data)
    layouts: dict[int, dict[str, NDArray[np.intp]]] = {}
    starts: dict[int, str] = {}
    for n in COUNTS:
        homogeneous = uniform[(n, floor)]
        planned = planned_leds(data.preview, dome, n, settings.preview_light_az_el_deg)
        # from the better of the two on the oracle's own cost: a greedy search from the
        # homogeneous layout alone can end above the planner (the coin at 20 and 30 lights)
        starts[n] = "optimal" if cost(planned) < cost(homogeneous) else "homogeneous"
        start = planned if starts[n] == "optimal" else homogeneous
        layouts[n] = {
            "homogeneous": homogeneous,
            "optimal": planned,
            "oracle": hindsight_exchange(n, dirs, cost, start, SWEEPS, STRIDE),
        }
    used = [k for per_n in layouts.values() for idx in per_n.values() for k in idx]
    fresh = fresh_shots(scene, settings, dirs, used)
    rows = []
    for n in COUNTS:
        lay = layouts[n]
        again = {
            k: normal_error(data.normals, np.stack([fresh[i] for i in idx]), dirs[idx])[0]
            for k, idx in lay.items()
        }
        low = " / ".join(str(int(np.sum(el[idx] < LOW_DEG))) for idx in lay.values())
        rows.append(
            f"| {scene} | {n} | {floor:g}° | {starts[n]} | {measured(lay['homogeneous']):.2f} / "
            f"{measured(lay['optimal']):.2f} / {measured(lay['oracle']):.2f} | "
            f"{again['homogeneous']:.2f} / {again['optimal']:.2f} / {again['oracle']:.2f} | "
            f"{100 * (1 - again['oracle'] / again['homogeneous']):.0f} % | {low} |"
        )
        print(rows[-1])
        sys.stdout.flush()
    return rows


def main(scenes: Iterable[str] | None = None) -> str:
    t0 = time.perf_counter()
    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    rows = [r for scene in (scenes or settings.scenes) for r in scene_rows(scene, settings)]
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.planner_sim_oracle` (total "
            f"{time.perf_counter() - t0:.0f} s). The scenes, preview and 240 candidate lights "
            "of `benchmarks.planner_sim_draws`, no lights out of service. Homogeneous: the "
            "scene's tuned floor (lowest mean over N). `optimal`: the planner from the preview. "
            f"Oracle: {SWEEPS} sweeps of single-light swaps from the better of the two (on its "
            "own cost), chosen on the measured error against the true normals (every other "
            "candidate per sweep, every other pixel and row): a near-bound of what a layout "
            "could do here, not a bound (a greedy search).",
            "",
            "Cells: mean normal error (°), homogeneous / `optimal` / oracle, on the images the "
            "oracle searched, then on a second shot of the same lights with fresh sensor noise "
            "(the fair comparison); the oracle's gain over the homogeneous layout on the fresh "
            f"shot; and how many of each layout's lights sit below {LOW_DEG:g}° elevation.",
            "",
            "| scene | N | floor | oracle's start | searched images | fresh noise | "
            f"oracle's gain | lights below {LOW_DEG:g}° |",
            "|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("planner_sim_oracle", md, DOC)
    print(md)
    return md


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__)
    args = positional_args()
    main(args[0].split(",") if args else None)
