"""What the fit's saturation rule cost fit.rti's HSH order, before and since 2026-11-25.

`rti-rig fit --model auto` chooses its model on a sample of pixels from which every pixel
saturated in *any* image is dropped; until 2026-11-25 fit.rti's HSH order
(:func:`rti_rig.app.usecases.fit_rti_order.hsh_order`) came from that choice too. The rule
drops those pixels (``select_model``: a clipped observation cannot be
held out honestly). On a glossy object lit from many directions that is most of the object: the
rule then judges the orders on the matte pixels alone, where a low order is enough. This prints,
for the homogeneous layouts of N = 18, 24, 36, 48 above 0°, 10° and 20° of the acquisition
(default: ../shared/data/neuralrti-example; the held-out lights of
``benchmarks.tradeoff_from.held_out_lights``), the share of sampled pixels the rule drops, the
order chosen with the rule (what shipped before 2026-11-25) and the order `rti-rig fit` writes
now (``written_rti_order``, the fit's own ``rti_order``: the clipped values kept for the order,
as the file itself is fitted on them), and the held-out relighting PSNR of HSH orders 1–3, so
the dB each choice gives up against the best order in hindsight can be read.

``--sim`` adds the simulator's five scenes (their 240 candidates clipped at white, 40 held-out
lights rendered without noise, as ``benchmarks.fit_rti_order_rules``).

Run: ``python -m benchmarks.fit_rti_order_saturation [--from ACQ/dirs.lp] [--sim]`` (prints
only).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from benchmarks.metrics import relight_psnr
from benchmarks.planner_real_data import reference, relight_model, written_rti_order
from benchmarks.tradeoff import TradeoffSettings, render_scene_data
from benchmarks.tradeoff_from import held_out_lights, load_acquisition_colour
from rti_rig.app.usecases.fit import SAMPLE_PIXELS
from rti_rig.app.usecases.fit_rti_order import hsh_order
from rti_rig.core.errors import ScheduleError
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.uniform import select_uniform_leds
from rti_rig.reconstruct.model_select import select_model
from rti_rig.reconstruct.stack import ImageStack

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "neuralrti-example"
NS = (18, 24, 36, 48)
FLOORS = (0.0, 10.0, 20.0)


def chosen_order(colour: np.ndarray, dirs: np.ndarray, drop_saturated: bool) -> int | None:
    """fit.rti's order chosen on the model choice alone, with or without its saturation rule
    (with it: what `rti-rig fit` wrote before 2026-11-25)."""
    stack = ImageStack(colour, saturation_level=1.0 if drop_saturated else None)
    choice = select_model(stack, dirs, max_pixels=SAMPLE_PIXELS)
    return hsh_order(None, choice.model, choice, len(dirs))[0]


Layout = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]


def real_layouts(
    lp: Path, ns: tuple[int, ...], floors: tuple[float, ...]
) -> list[tuple[int, float, Layout]]:
    """(N, floor, (grey, colour, lights, held-out grey, held-out lights, mask)) per homogeneous
    layout of the acquisition ``lp``, its held-out lights those of `bench tradeoff --from`."""
    grey, colour, dirs, names = load_acquisition_colour(lp)
    held = held_out_lights(dirs)
    keep = np.setdiff1d(np.arange(len(dirs)), held)
    _, mask = reference(grey, dirs)
    dome = DomeGeometry(dirs[keep], tuple(names[i] for i in keep))
    out = []
    for n in ns:
        if n >= len(keep):
            continue
        for floor in floors:
            try:
                idx = keep[select_uniform_leds(dome, n, floor)]
            except ScheduleError:
                continue
            out.append(
                (n, floor, (grey[idx], colour[idx], dirs[idx], grey[held], dirs[held], mask))
            )
    return out


def sim_layouts(
    scene: str, ns: tuple[int, ...], floors: tuple[float, ...]
) -> list[tuple[int, float, Layout]]:
    """The same on one of the simulator's scenes (240 candidates, 40 held-out lights rendered
    without noise, as ``benchmarks.fit_rti_order_rules``), its images clipped at white."""
    settings = TradeoffSettings(held_out_lights=40, ground_truth_lights=150)
    d = render_scene_data(scene, settings)
    cand = d.candidate_dirs
    dome = DomeGeometry(cand, tuple(f"c{i}" for i in range(len(cand))))
    grey, held_grey = d.candidate_images.mean(axis=-1), d.held_images.mean(axis=-1)
    out = []
    for n in ns:
        for floor in floors:
            sel = np.asarray(select_uniform_leds(dome, n, floor))
            layout = (grey[sel], d.candidate_images[sel], cand[sel], held_grey, d.held_dirs, None)
            out.append((n, floor, layout))
    return out


def rows(
    layouts: list[tuple[int, float, Layout]], name: str = ""
) -> tuple[list[str], list[tuple[float, float]]]:
    """One Markdown row per layout (see the module docstring), and per layout the dB below the
    best order in hindsight of the order chosen with the rule (before) and of what ships."""
    out: list[str] = []
    lost: list[tuple[float, float]] = []
    for n, floor, (grey, colour, dirs, held_grey, held_dirs, mask) in layouts:
        dropped = float((colour >= 1.0).any(axis=(0, 3) if colour.ndim == 4 else 0).mean())
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            psnr = {
                o: relight_psnr(
                    relight_model(grey, dirs, f"hsh{o}"), held_grey, held_dirs, 1.0, mask
                )
                for o in (1, 2, 3)
                if n >= (o + 1) ** 2
            }
            before = chosen_order(colour, dirs, True)
            ships = written_rti_order(colour, dirs)
        best = max(psnr.values())
        lost.append(
            tuple(best - psnr[o] if o is not None else float("nan") for o in (before, ships))  # type: ignore[arg-type]
        )

        def cell(o: int | None, psnr: dict = psnr, best: float = best) -> str:
            return "—" if o is None else f"{o} ({best - psnr[o]:.2f} dB below the best)"

        out.append(
            (f"| {name} " if name else "")
            + f"| {n} | {floor:g}° | {dropped:.0%} | {cell(before)} | {cell(ships)} | "
            + " / ".join(f"{psnr.get(o, float('nan')):.2f}" for o in (1, 2, 3))
            + " |"
        )
    return out, lost


def _summary(lost: list[tuple[float, float]], what: str) -> str:
    a = np.array(lost, dtype=float).reshape(-1, 2)
    return (
        f"{what}: over {len(a)} layouts, mean dB below the best HSH order in hindsight "
        f"{np.nanmean(a[:, 0]):.2f} with the rule (before), {np.nanmean(a[:, 1]):.2f} now; "
        f"the rule had chosen a lower-scoring order in {int(np.sum(a[:, 0] > a[:, 1] + 1e-9))} "
        f"and a higher-scoring one in {int(np.sum(a[:, 0] < a[:, 1] - 1e-9))}."
    )


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--from", dest="lp", type=Path, default=DATA / "dirs.lp")
    ap.add_argument(
        "--sim", action="store_true", help="also the simulator's five scenes (about a minute)"
    )
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    body, lost = rows(real_layouts(args.lp, NS, FLOORS), args.lp.parent.name)
    summaries = [_summary(lost, f"{args.lp.parent.name} (real)")]
    if args.sim:
        sim_lost: list[tuple[float, float]] = []
        for scene in TradeoffSettings().scenes:
            b, ls = rows(sim_layouts(scene, NS, FLOORS), scene)
            body += b
            sim_lost += ls
            summaries.append(_summary(ls, scene))
        summaries.append(_summary(sim_lost, "the five simulated scenes"))
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.fit_rti_order_saturation --from {args.lp}"
            + (" --sim" if args.sim else "")
            + f"` ({time.perf_counter() - t0:.0f} s).",
            "",
            "| acquisition | N | floor | image pixels the rule drops | order with the rule "
            "(before) | order `rti-rig fit` writes now (clipped values kept) | held-out PSNR of "
            "HSH 1 / 2 / 3 (dB) |",
            "|---|---|---|---|---|---|---|",
            *body,
            "",
            *[f"* {s}" for s in summaries],
        ]
    )
    print(md)
    return md


if __name__ == "__main__":
    main(sys.argv[1:])
