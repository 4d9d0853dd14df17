"""Planning time from a 24-megapixel preview, weight-free path (shape from shading).

A 6000×4000 sRGB preview of the simulated relief scene is planned for a 72-LED dome (the
neuralrti dome's `.lp` from tests/data) and for the simulated arm, for each method and objective,
N = 9 and 18. BLAS is held to one thread by the planner itself; the figure is the median of
``REPEATS`` runs in one process, measured on whatever machine runs it (2 cores is the target).

Run: ``python -m benchmarks.planning_time`` (writes its section of docs/benchmarks.md).
"""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

import cv2
import numpy as np

from benchmarks.report import machine_line, write_section
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.lp_format import read_lp
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.make_plan import plan_with_report
from rti_rig.planner.topography import planning_image
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

REPEATS = 5
LP = Path(__file__).resolve().parent.parent / "tests" / "data" / "neuralrti" / "dirs.lp"


def main() -> str:
    entries = read_lp(LP)
    dome = DomeGeometry(np.array([e.direction for e in entries]), tuple(e.name for e in entries))
    arm = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)
    scene = relief_scene(400, 600, seed=0)
    small = lambert_radiance(scene, direction_from_az_el(30.0, 50.0))
    srgb = np.where(small <= 0.0031308, 12.92 * small, 1.055 * small ** (1 / 2.4) - 0.055)
    preview = cv2.resize(
        (np.clip(srgb, 0, 1) * 255).astype(np.uint8), (6000, 4000), interpolation=cv2.INTER_CUBIC
    )
    assert preview.shape == (4000, 6000, 3)

    def median_s(fn) -> float:
        times = []
        for _ in range(REPEATS):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    prep = median_s(lambda: planning_image(preview))
    rows = []
    for rig_name, geometry in (("72-LED dome", dome), ("arm", arm)):
        for n in (9, 18):
            for method, objective in (
                ("uniform", "normals"),
                ("kmeans", "normals"),
                ("optimal", "normals"),
                ("optimal", "relight"),
            ):
                med = median_s(
                    lambda g=geometry, n=n, m=method, o=objective: plan_with_report(
                        preview, g, n, m, o, preview_light=(30.0, 50.0)
                    )
                )
                rows.append((rig_name, n, method, objective, med))
                print(f"{rig_name:12s} N={n:2d} {method:8s} {objective:8s} median {med:.3f} s")
    print(f"downsample + linearise 24 MP: median {prep:.3f} s")
    lines = [
        "Command: `python -m benchmarks.planning_time`. "
        + machine_line()
        + f" os.cpu_count() = {os.cpu_count()}; median of {REPEATS} runs each.",
        "",
        "Planning from a 6000×4000 uint8 sRGB preview with the weight-free path (shape from "
        "shading, light given). Every run includes downsampling to 256 px, shape from shading, "
        "the relief-scale fit, cast-shadow maps and the objective (the `uniform` row too, "
        "because it reports the expected error).",
        "",
        f"Downsample + linearise alone: {prep:.3f} s.",
        "",
        "| rig | N | method | objective | median s |",
        "|---|---|---|---|---|",
    ]
    lines += [f"| {r} | {n} | {m} | {o} | {t:.3f} |" for r, n, m, o, t in rows]
    worst = max(t for *_, t in rows)
    lines += ["", f"Slowest case: {worst:.3f} s (target ≤ 1 s)."]
    md = "\n".join(lines)
    write_section("planning_time", md)
    return md


if __name__ == "__main__":
    main()
