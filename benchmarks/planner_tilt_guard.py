"""What the tilt guard of ``plan --method optimal`` saves and costs, over paired draws.

``optimal`` hedges against a global tilt the preview cannot show with copies of the surface
tilted by 25° (a cost), and since 2026-12-03 also guards against it (a constraint: a swap may
not leave a plane tilted up to what the most tilt-robust even layout compared survives with
fewer than 3 lights facing it; ``rti_rig/planner/tilt_guard.py``). This runs the simulator's
five trade-off scenes at 3–20 lights, each N over :data:`DRAWS` paired draws with
:data:`REMOVED` of the 240 candidate lights out of service (``benchmarks.planner_sim_draws``'s
design), and plans each draw from the scene's preview without the guard, with it as shipped
(capped at 40°) and capped at 60°. Cells: mean normal error (°) of each, against the
homogeneous layout with the floor tuned
with hindsight (the best of 0/10/20/30° on the draws' mean). The last lines: geometric mean and
worst of the ratio to that layout over all cells, for each.

Run: ``python -m benchmarks.planner_tilt_guard`` (about 2 minutes; ``--write`` puts the table in
docs/research/planner.md).
"""

from __future__ import annotations

import sys
import time

import numpy as np

from benchmarks.planner_real_data import DOC, planned_leds
from benchmarks.planner_sim_draws import paired_draws
from benchmarks.report import write_section
from benchmarks.tradeoff import TradeoffSettings, normal_error, render_scene_data
from rti_rig.planner import tilt_guard
from rti_rig.planner.uniform import select_uniform_leds

COUNTS = (3, 4, 5, 6, 8, 12, 20)
DRAWS = 6
REMOVED = 24
FLOORS = (0.0, 10.0, 20.0, 30.0)
SEED = 7
SHIPPED_CAP = tilt_guard.MAX_GUARD_DEG
#: (label, the guard's cap in degrees; None: unguarded)
VARIANTS: tuple[tuple[str, float | None], ...] = (
    ("unguarded", None),
    (f"guarded to {SHIPPED_CAP:g}° (ships)", SHIPPED_CAP),
    ("guarded to 60°", 60.0),
)


def scene_cells(scene: str, settings: TradeoffSettings) -> dict[int, dict[str, list[float]]]:
    """Per N: the draws' errors of each of :data:`VARIANTS` and each floor's even layout."""
    data = render_scene_data(scene, settings)
    cand = data.candidate_dirs
    rng = np.random.default_rng(SEED)
    out: dict[int, dict[str, list[float]]] = {}
    for n, keep, sub in paired_draws(cand, COUNTS, DRAWS, REMOVED, rng):
        chosen: dict[str, np.ndarray] = {}
        for f in FLOORS:
            chosen[f"u{f:g}"] = keep[select_uniform_leds(sub, n, f)]
        for label, cap in VARIANTS:
            tilt_guard.ENABLED, tilt_guard.MAX_GUARD_DEG = cap is not None, cap or SHIPPED_CAP
            try:
                picked = planned_leds(data.preview, sub, n, settings.preview_light_az_el_deg)
            finally:
                tilt_guard.ENABLED, tilt_guard.MAX_GUARD_DEG = True, SHIPPED_CAP
            chosen[label] = keep[picked]
        cell = out.setdefault(n, {})
        for label, idx in chosen.items():
            err = normal_error(data.normals, data.candidate_images[idx], cand[idx])[0]
            cell.setdefault(label, []).append(float(err))
    return out


def main() -> str:
    """Run every scene, print its row as it comes, and write the docs section when asked."""
    t0 = time.perf_counter()
    settings = TradeoffSettings()
    rows: list[str] = []
    ratios: dict[str, list[float]] = {label: [] for label, _ in VARIANTS}
    for scene in settings.scenes:
        cells = []
        for errs in scene_cells(scene, settings).values():
            tuned = min(float(np.mean(errs[f"u{f:g}"])) for f in FLOORS)
            means = [float(np.mean(errs[label])) for label, _ in VARIANTS]
            for (label, _), m in zip(VARIANTS, means, strict=True):
                ratios[label].append(m / tuned)
            cells.append(" → ".join(f"{m:.2f}" for m in means) + f" ({tuned:.2f})")
        rows.append(f"| {scene} | " + " | ".join(cells) + " |")
        print(rows[-1], f"({time.perf_counter() - t0:.0f} s)")
        sys.stdout.flush()
    summary = [
        f"- {label}: ratio to the tuned even layout, geometric mean "
        f"{np.exp(np.mean(np.log(r))):.3f}, worst {max(r):.2f}"
        for label, r in ratios.items()
    ]
    print("\n".join(summary))
    md = "\n".join(
        [
            "Command: `python -m benchmarks.planner_tilt_guard` "
            f"(total {time.perf_counter() - t0:.0f} s, seed {SEED}, {DRAWS} draws, {REMOVED} "
            "lights out of service). Cells: mean normal error (°) of `optimal` "
            + " → ".join(label for label, _ in VARIANTS)
            + " (the tuned even layout's).",
            "",
            "| scene | " + " | ".join(f"N = {n}" for n in COUNTS) + " |",
            "|---|" + "---|" * len(COUNTS),
            *rows,
            "",
            *summary,
        ]
    )
    write_section("planner_tilt_guard", md, DOC)
    return md


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__)
    main()
