"""Which relighting file a sparse session should be read from: held-out PSNR of each basis.

On a real acquisition (default: ../shared/data/neuralrti-example), with the lights
``benchmarks.tradeoff_from.held_out_lights`` holds out (one per elevation band, seeded), the
homogeneous layouts of N = 6, 9, 12, 18 at floors 0°, 10°, 20° are fitted with HSH of order
1, 2, 3 and the PTM, each relit to the held-out lights (PSNR, data range 1, as
``benchmarks.metrics.relight_psnr``), beside the HSH order `rti-rig fit`'s ``auto`` now writes
to fit.rti (:func:`rti_rig.app.usecases.fit_rti_order.hsh_order` on the model choice of the
layout's own images — here the benchmark's grey images of at most 256 px, so in close cases
the fit of the full colour images may choose otherwise) and the order it wrote before (order 2,
or none below 9 lights).

Run: ``python -m benchmarks.fit_rti_order [--data DIR] [--write]`` (``--write`` replaces the
section ``fit_rti_order`` of docs/reconstruction.md).
"""

from __future__ import annotations

import argparse
import time
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from benchmarks.metrics import relight_psnr
from benchmarks.planner_real_data import relight_model
from benchmarks.report import machine_line, write_section
from benchmarks.tradeoff_from import held_out_lights, load_acquisition
from rti_rig.app.usecases.fit_rti_order import hsh_order
from rti_rig.core.errors import ScheduleError
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.uniform import select_uniform_leds
from rti_rig.reconstruct.model_select import select_model

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "neuralrti-example"
DOC = Path(__file__).resolve().parent.parent / "docs" / "reconstruction.md"
NS = (6, 9, 12, 18)
FLOORS = (0.0, 10.0, 20.0)
BASES = {"hsh1": 4, "ptm": 6, "hsh2": 9, "hsh3": 16}


Layout = tuple[int, float, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def real_layouts(
    data: Path, ns: tuple[int, ...] = NS, floors: tuple[float, ...] = FLOORS
) -> Iterator[Layout]:
    """(N, floor, images, lights, held-out images, held-out lights, mask) of each homogeneous
    layout of an acquisition's lights not held out (``held_out_lights``); a floor with fewer
    lights above it than N is skipped."""
    images, dirs, names = load_acquisition(data / "dirs.lp")
    held = held_out_lights(dirs)
    keep = np.setdiff1d(np.arange(len(dirs)), held)
    dome = DomeGeometry(dirs[keep], tuple(names[i] for i in keep))
    mask = images.max(axis=0) > 0.02
    for n in (n for n in ns if n <= len(keep)):
        for floor in floors:
            try:
                sel = keep[np.asarray(select_uniform_leds(dome, n, floor))]
            except ScheduleError:
                continue
            yield n, floor, images[sel], dirs[sel], images[held], dirs[held], mask


def rows(data: Path) -> list[str]:
    """One table row per N and floor."""
    out = []
    for n, floor, im, lights, held_im, held_l, mask in real_layouts(data):
        psnr = {}
        for basis, terms in BASES.items():
            if n >= terms:
                mdl = relight_model(im, lights, basis)
                psnr[basis] = relight_psnr(mdl, held_im, held_l, 1.0, mask)
        choice = select_model(im, lights)
        order, _ = hsh_order(None, choice.model, choice, n)
        before = choice.model if choice.model.startswith("hsh") else ("hsh2" if n >= 9 else "—")
        cells = [f"{psnr[b]:.1f}" if b in psnr else "—" for b in BASES]
        before = f"{before} ({psnr[before]:.1f} dB)" if before in psnr else before
        now = f"hsh{order} ({psnr[f'hsh{order}']:.1f} dB)" if order else "—"
        out.append(
            f"| {n} | {floor:g}° | " + " | ".join(cells) + f" | {choice.model} | {before} | {now} |"
        )
    return out


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, default=DATA)
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # ill-conditioned sparse fits are what is measured
        body = rows(args.data)
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.fit_rti_order --write` ({time.perf_counter() - t0:.0f}"
            f" s). {machine_line()} Acquisition: `{args.data.name}`, the lights "
            "`benchmarks.tradeoff_from` holds out (one per elevation band) never fitted; each "
            "homogeneous layout of the others fitted with each basis and relit to them: PSNR "
            "(dB, linear luminance, data range 1). One acquisition, one layout per cell.",
            "",
            "| N | floor | HSH order 1 | PTM | HSH order 2 | HSH order 3 | auto's model | fit.rti "
            "before | fit.rti now |",
            "|---|---|---|---|---|---|---|---|---|",
            *body,
        ]
    )
    print(md)
    if args.write:
        write_section("fit_rti_order", md, DOC)
    return md


if __name__ == "__main__":
    main()
