"""Where the planner loses on the simulator, and why: the error of each layout split by cause.

``benchmarks.planner_sim_draws`` shows the ``optimal`` planner losing to a tuned homogeneous
layout on some simulated scenes at high light counts. This benchmark takes two layouts on the
same scenes (the planner's, from the same preview shot, and the homogeneous one with the floor
that scores best on the scene; all 240 candidates, no draws) and renders them once per physical
effect, so
each loss can be traced to what the simulator renders and what the planner's model assumes:

* ``noise``: pure Lambertian images (no cast shadow, no specular lobe) with sensor noise — the
  part of the error the planner's Cramér–Rao term models;
* ``shadows``: cast shadows only, noise-free — what partly and fully shadowed observations cost
  the robust fit (a pixel on a shadow's edge is partly lit: darker than Lambert, not dark enough
  to be rejected);
* ``specular``: the specular lobe only, noise-free (scenes that declare one);
* ``all``: everything, as the benchmarks score it.

It also prints the planner's own expected-error terms for both layouts (variance and the prior
on non-Lambertian reflectance: :class:`rti_rig.planner.objectives.NormalsObjective`), to show which
term made it choose what it chose. Errors are mean angles (°) over every pixel, robust
photometric stereo against the true normals (``benchmarks.tradeoff.normal_error``).

Run: ``python -m benchmarks.planner_sim_losses`` (writes its section of docs/research/planner.md).
"""

from __future__ import annotations

import sys
import time

import numpy as np
from numpy.typing import NDArray

from benchmarks.planner_real_data import DOC
from benchmarks.report import write_section
from benchmarks.tradeoff import (
    TradeoffSettings,
    normal_error,
    render_scene_data,
    scene_camera,
)
from rti_rig.core.geometry import az_el_from_direction, fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.make_plan import plan_with_report
from rti_rig.planner.objectives import HELD_OUT, NormalsObjective, candidates_for
from rti_rig.planner.surface_estimate import estimate_surface, sample_surface
from rti_rig.planner.uniform import select_uniform_leds

COUNTS = (6, 12, 20, 30)
FLOORS = (0.0, 10.0, 20.0, 30.0)
NOISE_REPEATS = 3


def _terms(obj: NormalsObjective, chosen: NDArray[np.intp]) -> tuple[float, float]:
    """The objective's variance and reflectance-prior terms (° RMS) for a layout."""
    m = obj.outer[:, chosen].sum(axis=1)[:, None]
    var = float(np.degrees(np.sqrt(obj._variance(m) @ obj.wts))[0])
    prior = 0.0
    if obj.tau2 > 0:
        r = obj.cross[:, chosen].sum(axis=1)[:, None]
        prior = float(np.degrees(np.sqrt(obj._bias(m[..., : obj.n_bias], r) @ obj.wts_bias))[0])
    return var, prior


def main() -> str:
    t0 = time.perf_counter()
    settings = TradeoffSettings(held_out_lights=1, ground_truth_lights=50)
    cand = fibonacci_cap(settings.candidates, 3.0, 87.0)
    dome = DomeGeometry(cand, tuple(f"c{i:03d}" for i in range(len(cand))))
    candidates = candidates_for(dome)
    rows: list[str] = []
    for name in settings.scenes:
        scene, camera_shot = scene_camera(name, settings)
        truth = np.asarray(scene.normals, dtype=np.float64)
        # the very preview shot that benchmarks.planner_sim_draws plans from
        preview = render_scene_data(name, settings).preview
        surface = estimate_surface(preview, settings.preview_light_az_el_deg)
        _, cel = az_el_from_direction(cand)
        held = fibonacci_cap(HELD_OUT, float(cel.min()), float(cel.max()))
        obj = NormalsObjective(sample_surface(surface, candidates, held), candidates)
        variants: list[tuple[str, frozenset[str], bool]] = [
            ("noise", frozenset(), True),
        ]
        if "shadows" in scene.passes:
            variants.append(("shadows", frozenset({"shadows"}), False))
        if "specular" in scene.passes:
            variants.append(("specular", frozenset({"specular"}), False))
        variants.append(("all", frozenset(scene.passes), True))

        def errors(
            idx: NDArray[np.intp], variants=variants, shoot=camera_shot, truth=truth
        ) -> dict:
            out = {}
            for label, passes, noisy in variants:
                vals = []
                for rep in range(NOISE_REPEATS if noisy else 1):
                    rng = np.random.default_rng(100 + rep) if noisy else None
                    imgs = np.stack([shoot(cand[i], rng, passes) for i in idx])
                    vals.append(normal_error(truth, imgs, cand[idx])[0])
                out[label] = float(np.mean(vals))
            return out

        uni = {(n, f): errors(select_uniform_leds(dome, n, f)) for n in COUNTS for f in FLOORS}
        # one floor per scene, as benchmarks.planner_sim_draws tunes it: lowest mean over N
        floor = min(FLOORS, key=lambda f: float(np.mean([uni[(n, f)]["all"] for n in COUNTS])))
        for n in COUNTS:
            sched, _ = plan_with_report(
                preview, dome, n, "optimal", "normals", settings.preview_light_az_el_deg
            )
            opt_idx = np.array([s.led for s in sched.steps], dtype=np.intp)
            opt = errors(opt_idx)
            uni_idx = select_uniform_leds(dome, n, floor)
            _, el_u = az_el_from_direction(cand[uni_idx])
            _, el_o = az_el_from_direction(cand[opt_idx])
            tu, to = _terms(obj, uni_idx), _terms(obj, opt_idx)

            def cell(key: str, u=uni[(n, floor)], o=opt) -> str:
                return f"{u[key]:.2f} / {o[key]:.2f}" if key in o else "—"

            rows.append(
                f"| {name} | {n} | {floor:g}° | {el_u.min():.0f}° / {el_o.min():.0f}° | "
                + " | ".join(cell(k) for k in ("all", "noise", "shadows", "specular"))
                + f" | {tu[0]:.2f} / {to[0]:.2f} | {tu[1]:.2f} / {to[1]:.2f} |"
            )
            print(rows[-1])
            sys.stdout.flush()
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.planner_sim_losses` (total "
            f"{time.perf_counter() - t0:.0f} s). Full candidate set (240), one plan per scene "
            "and N from the preview `benchmarks.planner_sim_draws` uses; homogeneous floor "
            "tuned with hindsight per scene (lowest mean of the `all` column over N).",
            "",
            "Each cell: tuned homogeneous / `optimal` (normals). Measured: mean normal error (°) "
            "with only that effect rendered (noise: Lambertian + sensor noise, mean of "
            f"{NOISE_REPEATS} noise draws; shadows, specular: noise-free). Model: the planner's "
            "expected-error terms (° RMS at its assumed 2 % noise): variance, prior on "
            "non-Lambertian reflectance (relative to the fit on all usable lights).",
            "",
            "| scene | N | floor | lowest light | all | noise | shadows | specular "
            "| model: variance | model: reflectance prior |",
            "|---|---|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    write_section("planner_sim_losses", md, DOC)
    return md


if __name__ == "__main__":
    from benchmarks.report import exit_on_help

    exit_on_help(__doc__)
    main()
