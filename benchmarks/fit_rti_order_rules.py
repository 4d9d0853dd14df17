"""fit.rti's HSH order rule, measured: which cross-validation rule loses least on held-out lights.

`rti-rig fit --model auto` picks fit.rti's HSH order from 5-fold cross-validation over the
layout's own lights, the lowest order within 5 % of the best HSH order's held-out RMS
(:mod:`rti_rig.app.usecases.fit_rti_order`). This scores that rule and variants (10 folds;
tolerances 0–2 %) on homogeneous layouts of 6–36 lights at floors 0°–30°: on the shared real
acquisition (its lights ``benchmarks.tradeoff_from`` holds out never fitted) and on the
simulator's five scenes (150 held-out lights rendered without noise). Each layout's loss is the
held-out PSNR of the best HSH order in hindsight minus that of the order the rule picks.
Prints a line per rule (no ``--write``: docs/reconstruction.md quotes a run).

Run: ``python -m benchmarks.fit_rti_order_rules`` (about 3 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from benchmarks.fit_rti_order import real_layouts
from benchmarks.metrics import relight_psnr
from benchmarks.planner_real_data import relight_model
from benchmarks.tradeoff import TradeoffSettings, render_scene_data
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.uniform import select_uniform_leds
from rti_rig.reconstruct.model_select import select_model

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "neuralrti-example"
#: tolerances on the held-out RMS (relative to the best HSH order's) and fold counts measured
TOLS = (0.05, 0.02, 0.01, 0.0)
FOLDS = (5, 10)
NS = (6, 9, 12, 18, 24, 36)
FLOORS = (0.0, 10.0, 20.0, 30.0)

Case = tuple[str, int, float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def cases(data: Path) -> Iterator[Case]:
    """(scene, N, floor, images, lights, held-out images, held-out lights, mask) per layout."""
    for n, f, im, lights, held_im, held_l, mask in real_layouts(data, NS, FLOORS):
        yield "real", n, f, im, lights, held_im, held_l, mask
    settings = TradeoffSettings(held_out_lights=40, ground_truth_lights=150)
    for scene in settings.scenes:
        d = render_scene_data(scene, settings)
        grey, held_grey = d.candidate_images.mean(axis=-1), d.held_images.mean(axis=-1)
        sim = DomeGeometry(d.candidate_dirs, tuple(f"c{i}" for i in range(len(d.candidate_dirs))))
        everywhere = np.ones(grey.shape[1:], dtype=bool)
        for n in NS:
            for f in FLOORS:
                sel = np.asarray(select_uniform_leds(sim, n, f))
                yield (
                    scene,
                    n,
                    f,
                    grey[sel],
                    d.candidate_dirs[sel],
                    held_grey,
                    d.held_dirs,
                    everywhere,
                )


def losses(data: Path) -> dict[tuple[int, float], list[tuple[str, float]]]:
    """(folds, tolerance) → (scene, dB lost against the best HSH order) per layout."""
    out: dict[tuple[int, float], list[tuple[str, float]]] = {}
    for scene, n, _f, im, lights, held_im, held_l, mask in cases(data):
        psnr = {
            o: relight_psnr(relight_model(im, lights, f"hsh{o}"), held_im, held_l, 1.0, mask)
            for o in (1, 2, 3)
            if n >= (o + 1) ** 2
        }
        best = max(psnr.values())
        for k in FOLDS:
            choice = select_model(im, lights, holdout=k)
            scored = [e for e in choice.evidence if e.model.startswith("hsh") and e.rmse]
            if not scored:
                continue
            least = min(e.rmse for e in scored if e.rmse is not None)
            for tol in TOLS:
                pick = min(
                    (e for e in scored if e.rmse is not None and e.rmse <= least * (1 + tol)),
                    key=lambda e: e.n_coefficients,
                )
                out.setdefault((k, tol), []).append((scene, best - psnr[int(pick.model[-1])]))
    return out


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, default=DATA)
    args = ap.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ill-conditioned sparse fits are what is measured
        res = losses(args.data)
    lines = ["| folds | tolerance | mean dB lost | real | simulator | layouts > 1 dB | worst |"]
    lines.append("|---|---|---|---|---|---|---|")
    for (k, tol), v in sorted(res.items()):
        loss = np.array([x for _, x in v])
        real = np.array([x for s, x in v if s == "real"])
        sim = np.array([x for s, x in v if s != "real"])
        lines.append(
            f"| {k} | {tol:.0%} | {loss.mean():.2f} | {real.mean():.2f} | {sim.mean():.2f} | "
            f"{(loss > 1).sum()} of {len(loss)} | {loss.max():.1f} |"
        )
    md = "\n".join(lines)
    print(md)
    return md


if __name__ == "__main__":
    main()
