"""Design-decision time of `run --adaptive --lights N --objective relight` against the normals
objective, on the states `benchmarks.adaptive_time` times (N/2 images so far, N planned; the
simulator's relief scene; a 200-LED dome and the arm), BLAS on one thread as the chooser runs.

The relight score renders every candidate light left out (up to 200 on the dome) at the
simulated pixels, where the normals score renders only the designs' lights; the fits it runs
(a linear basis) are cheaper than the robust fits of the normals score.

Run: ``python -m benchmarks.adaptive_relight_time [--repeats 3]`` (prints; writes nothing).
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np
from threadpoolctl import threadpool_limits

from benchmarks.adaptive_time import _median, _state
from rti_rig.app.usecases.adaptive import relight_fit, robust_fit, sample_pixels, small_grey
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.adaptive import START_LIGHTS, choose_in_design, object_model
from rti_rig.planner.adaptive_bias import simulate_error_deg
from rti_rig.planner.objectives import candidates_for
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

NS = (6, 12, 18, 36, 50, 100)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    dome = DomeGeometry(fibonacci_cap(200, 5.0), tuple(f"led_{i:03d}" for i in range(200)))
    arm = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)
    scene = relief_scene(85, 128, seed=0)
    frame = np.random.default_rng(0).integers(0, 65535, (4000, 6000, 3), dtype=np.uint16)
    load = os.getloadavg()
    print("| rig | N | candidates | normals design decision s | relight design decision s |")
    print("|---|---|---|---|---|")
    for rig_name, geometry in (("200-LED dome", dome), ("arm", arm)):
        cands = candidates_for(geometry).directions
        for n in NS:
            if n > len(cands) - 1:
                continue
            lights = cands[np.linspace(0, len(cands) - 1, n).round().astype(int)]
            images = np.stack([lambert_radiance(scene, d).mean(axis=-1) for d in lights])
            images = images.astype(np.float32)
            half = max(START_LIGHTS, n // 2)
            avail = np.ones(len(cands), dtype=bool)
            avail[np.linspace(0, len(cands) - 1, half).round().astype(int)] = False
            samples = sample_pixels(images)[:half]

            def decide(  # type: ignore[no-untyped-def]
                objective: str,
                samples=samples,
                lights=lights[:half],
                images=images[:half],
                avail=avail,
                cands=cands,
                n=n,
            ) -> None:
                sample_pixels(small_grey(frame)[None])
                state = _state(samples, lights, images)
                simulate_error_deg(object_model(state), lights, robust_fit)
                choose_in_design(
                    state,
                    cands,
                    avail,
                    n,
                    fit=robust_fit,
                    objective=objective,
                    relight=relight_fit if objective == "relight" else None,
                )

            with threadpool_limits(limits=1, user_api="blas"):
                t_n = _median(lambda d=decide: d("normals"), args.repeats)
                t_r = _median(lambda d=decide: d("relight"), args.repeats)
            print(f"| {rig_name} | {n} | {len(cands)} | {t_n:.3f} | {t_r:.3f} |", flush=True)
    print(
        f"\nMedians of {args.repeats}; load average {load[0]:.1f} at the start, "
        f"{os.getloadavg()[0]:.1f} at the end."
    )


if __name__ == "__main__":
    main(sys.argv[1:])
