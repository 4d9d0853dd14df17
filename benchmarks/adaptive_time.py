"""Planning time against the number of lights: every adaptive decision, and `plan --method
optimal`, at N = 6 … 100 on a dome and on an arm.

* **Adaptive decision** (what `run --adaptive` does between two images): shrink the newest
  24-megapixel frame (6000×4000 RGB, 16-bit) to the fit's 128 px and sample it, and sample it
  at full size; robust photometric stereo on the samples of the images so far, the estimate,
  the stop's evidence at full size (the robust fit of the full-size samples, their unsolved
  share and misfit bound), and the choice: light by light among
  the rig's candidates (N images so far, as `--until-error` alone does: within the design for
  the next guessed N of ``planner.adaptive_until``; ``--greedy``: format 5's bound-only choice),
  or the rest of an
  N-light design (N/2 images so far, as `--lights N` does; for ``--objective normals`` and
  ``relight``, whose score renders every candidate left out). Targets: ≤ 0.2 s on 2
  cores. The N images are the simulator's relief scene rendered at the fit's size (the shrink
  is timed on a real 24-MP frame, once per decision, as in a session).
* **`plan --method optimal`** with no preview (a level surface, as `plan --rig RIG --lights N
  --method optimal`): a 200-LED Fibonacci dome (a 72-LED dome cannot take 100 lights) and the
  simulated arm. Target ≤ 1 s at 100 lights. Beside it `plan --method uniform` in the same run
  (the ratio optimal/uniform does not depend on the machine's load as the seconds do), and
  `optimal` from a preview (the simulator's relief scene, 192×256, its light given), where the
  sampled pixels are all different and the planner does the most work.

Median of ``--repeats`` runs.
Run: ``python -m benchmarks.adaptive_time [--write]`` (``--write``: docs/adaptive.md).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

from benchmarks.adaptive import DOC
from benchmarks.report import machine_line, write_section
from rti_rig.app.usecases.adaptive import (
    camera_sample,
    fit_sample,
    relief_px,
    relight_fit,
    robust_fit,
    sample_index,
    sample_pixels,
    small_grey,
)
from rti_rig.core.geometry import direction_from_az_el, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.adaptive import START_LIGHTS, choose_in_design, choose_next, object_model
from rti_rig.planner.adaptive_bias import simulate_error_deg
from rti_rig.planner.adaptive_until import (
    MISFIT_NOISE_K,
    choose_until,
    misfit_deg,
    unsolved_fraction,
)
from rti_rig.planner.make_plan import plan_with_report
from rti_rig.planner.objectives import candidates_for
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

NS = (6, 9, 12, 18, 24, 36, 50, 75, 100)
#: ``--greedy``: time the light-by-light decision of format 5 (the bound's best light)
GREEDY = False


def _state(samples: np.ndarray, lights: np.ndarray, images: np.ndarray):  # type: ignore[no-untyped-def]
    """The chooser's state as ``AdaptiveChooser.state`` makes it (bias-aware: with the
    relief of the small images and where the sample lies in them)."""
    shape = images.shape[1:3]
    where = np.unravel_index(sample_index(shape[0] * shape[1]), shape)
    state = fit_sample(samples, lights, where, relief_px(images, lights))
    assert state is not None
    return state


def _image_evidence(camera: np.ndarray, lights: np.ndarray) -> None:
    """The stop's evidence at the camera's resolution, as ``AdaptiveChooser.image_evidence``
    reads it in every decision: the robust fit of the images' full-size samples, the share of
    them unsolved and the misfit bound (``planner.adaptive_until``)."""
    state = fit_sample(camera, lights)
    assert state is not None
    unsolved_fraction(state.valid)
    assert state.residual is not None and state.used is not None and state.valid is not None
    misfit_deg(
        state.residual, state.used, state.albedo, state.valid, state.lit, state.lights,
        MISFIT_NOISE_K,
    )  # fmt: skip


def _median(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--max-optimal-n", type=int, default=100)
    ap.add_argument("--write", action="store_true")
    ap.add_argument(
        "--no-fitted-design",
        action="store_true",
        help="time the design decisions without planner.adaptive_optimal's design (offered in "
        "what ships): to compare",
    )
    ap.add_argument(
        "--greedy",
        action="store_true",
        help="time format 5's light-by-light decision (the bound's best light) instead of the "
        "design for a guessed N that grows: to compare",
    )
    args = ap.parse_args(argv)
    global GREEDY
    GREEDY = args.greedy
    if args.no_fitted_design:
        import rti_rig.planner.adaptive as adaptive_planner

        adaptive_planner.FITTED_DESIGN = False
    dome = DomeGeometry(fibonacci_cap(200, 5.0), tuple(f"led_{i:03d}" for i in range(200)))
    arm = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)
    scene = relief_scene(85, 128, seed=0)
    preview_scene = relief_scene(192, 256, seed=0)
    preview = lambert_radiance(preview_scene, direction_from_az_el(30.0, 50.0)).astype(np.float32)
    load_before = os.getloadavg()
    frame = np.random.default_rng(0).integers(0, 65535, (4000, 6000, 3), dtype=np.uint16)
    shrink = _median(lambda: small_grey(frame), args.repeats)
    full_sample = _median(lambda: camera_sample(frame), args.repeats)
    print(f"shrink 24 MP -> 128 px: {shrink:.3f} s; full-size sample {full_sample:.4f} s")
    rows = []
    for rig_name, geometry in (("200-LED dome", dome), ("arm", arm)):
        cands = candidates_for(geometry).directions
        for n in NS:
            if n > len(cands) - 1:
                continue
            lights = cands[np.linspace(0, len(cands) - 1, n).round().astype(int)]
            images = np.stack([lambert_radiance(scene, d).mean(axis=-1) for d in lights])
            images = images.astype(np.float32)
            available = np.ones(len(cands), dtype=bool)

            samples = sample_pixels(images)  # each image sampled once, as it arrived

            def decide(
                samples=samples, lights=lights, available=available, cands=cands, images=images
            ) -> None:
                # the newest frame shrunk and sampled, and sampled at full size; the fit on the
                # sample (and the relief on the small images), the bias-aware estimate (a
                # simulated fit), the stop's image evidence at full size (the small images'
                # samples stand in for the earlier frames' full-size ones: the same shape and
                # work), the choice
                sample_pixels(small_grey(frame)[None])
                camera_sample(frame)
                state = _state(samples, lights, images)
                _image_evidence(samples, lights)
                simulate_error_deg(object_model(state), lights, robust_fit)
                if GREEDY:  # format 5's path: the bound's best light
                    choose_next(state, cands, available)
                else:  # N unknown: the design for a guessed N that grows (adaptive_until)
                    choose_until(state, cands, available, len(cands), fit=robust_fit)

            half = max(START_LIGHTS, n // 2)
            avail_half = np.ones(len(cands), dtype=bool)
            avail_half[np.linspace(0, len(cands) - 1, half).round().astype(int)] = False

            def decide_design(
                objective: str,
                samples=samples[:half],
                lights=lights[:half],
                available=avail_half,
                cands=cands,
                n=n,
                images=images[:half],
            ) -> None:
                sample_pixels(small_grey(frame)[None])
                camera_sample(frame)
                state = _state(samples, lights, images)
                _image_evidence(samples, lights)
                simulate_error_deg(object_model(state), lights, robust_fit)
                choose_in_design(
                    state,
                    cands,
                    available,
                    n,
                    fit=robust_fit,
                    objective=objective,
                    relight=relight_fit if objective == "relight" else None,
                )

            # as AdaptiveChooser.decide runs them: BLAS on one thread
            with threadpool_limits(limits=1, user_api="blas"):
                t_dec = _median(decide, args.repeats)
                t_des = _median(lambda d=decide_design: d("normals"), args.repeats)
                t_rel = _median(lambda d=decide_design: d("relight"), args.repeats)
            t_opt = t_uni = t_prev = float("nan")
            if n <= args.max_optimal_n:
                t_uni = _median(
                    lambda g=geometry, n=n: plan_with_report(None, g, n, "uniform", "normals"),
                    args.repeats,
                )
                t_opt = _median(
                    lambda g=geometry, n=n: plan_with_report(None, g, n, "optimal", "normals"),
                    args.repeats,
                )
                t_prev = _median(
                    lambda g=geometry, n=n: plan_with_report(
                        preview, g, n, "optimal", "normals", (30.0, 50.0)
                    ),
                    args.repeats,
                )
            rows.append((rig_name, n, len(cands), t_dec, t_des, t_rel, t_opt, t_uni, t_prev))
            print(
                f"{rig_name:12s} N={n:3d} candidates={len(cands)} adaptive decision "
                f"{t_dec:.3f} s, design decision {t_des:.3f} s (relight {t_rel:.3f} s), "
                f"optimal plan {t_opt:.2f} s "
                f"(uniform {t_uni:.3f} s, "
                f"{t_opt / t_uni:.1f}×), from a preview {t_prev:.2f} s ({t_prev / t_uni:.1f}×)",
                flush=True,
            )
    decisions_only = args.max_optimal_n <= 0
    cmd = "python -m benchmarks.adaptive_time --repeats " + str(args.repeats)
    cmd += " --max-optimal-n 0" if decisions_only else ""
    cmd += " --no-fitted-design" if args.no_fitted_design else ""
    cmd += " --greedy" if args.greedy else ""
    lines = [
        f"Command: `{cmd} --write`. "
        + machine_line()
        + f" os.cpu_count() = {os.cpu_count()}; medians of {args.repeats} runs. Other jobs "
        "shared the 2 cores while this ran: load average (1, 5, 15 min) "
        + "/".join(f"{x:.1f}" for x in load_before)
        + " at the start, "
        + "/".join(f"{x:.1f}" for x in os.getloadavg())
        + " at the end.",
        "",
        f"Shrinking one 24-MP frame (6000×4000×3, 16-bit) to the fit's 128 px: {shrink:.3f} s; "
        f"its 2000-pixel sample at full size (`camera_sample`): {full_sample:.4f} s (both "
        "inside every decision below, with sampling the new image's 2000 pixels, and the "
        "stop's evidence at full size: the robust fit of every image's full-size sample, its "
        "unsolved share and misfit bound).",
        "",
    ]
    if decisions_only:
        lines += [
            "| rig | N | candidates | light-by-light decision s, N images so far (target ≤ 0.2) "
            "| design decision s, N/2 images so far, N planned (target ≤ 0.2) "
            "| the same with `--objective relight` s |",
            "|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r} | {n} | {c} | {d:.3f} | {e:.3f} | {x:.3f} |" for r, n, c, d, e, x, *_ in rows
        ]
    else:
        lines += [
            "| rig | N | candidates | light-by-light decision s, N images so far (target ≤ 0.2) "
            "| design decision s, N/2 images so far, N planned (target ≤ 0.2) "
            "| the same with `--objective relight` s "
            "| `plan --method optimal` s (target ≤ 1) | `uniform` s | optimal / uniform "
            "| `optimal` from a preview s (target ≤ 1) | from a preview / uniform |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r} | {n} | {c} | {d:.3f} | {e:.3f} | {x:.3f} | {o:.2f} | {u:.3f} | {o / u:.1f}× "
            f"| {p:.2f} | {p / u:.1f}× |"
            for r, n, c, d, e, x, o, u, p in rows
        ]
    md = "\n".join(lines)
    print(md)
    if args.write:
        write_section("adaptive_time", md, DOC)
    return md


if __name__ == "__main__":
    main(sys.argv[1:])
