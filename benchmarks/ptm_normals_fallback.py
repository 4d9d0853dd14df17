"""Which normals a PTM fit should write where its own cannot be trusted: robust PS or Lambert.

`rti-rig fit --model ptm` (or `auto` choosing the PTM) reads its normal maps from the PTM,
except where the PTM is ridge-regularised (one ring, the horizon) or over its noise-gain limit
(lights on one side only): there its Lambertian reading was 22-71° off. This measures, on the
simulator's scenes (as benchmarks.fit_auto_normals renders them), the mean normal error of the
PTM's reading, of robust photometric stereo and of least-squares Lambert on such light sets,
so the fallback is chosen by evidence: no estimator is best on every scene. Since 2026-12-07 it
also measures well-conditioned low bands, where the reading extrapolates (the column "reading
bias": ``reading_bias_deg`` of the lights), and says
which normals a fit writes on each set.

Run: ``python -m benchmarks.ptm_normals_fallback [--write]`` (``--write`` replaces the section
``ptm_normals_fallback`` of docs/reconstruction.md).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

from benchmarks.fit_auto_normals import DOC, SCENES, SIZE, angles, render, rings
from benchmarks.report import machine_line, write_section
from rti_rig.app.usecases.fit import conditioned_normal_source
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct import fit_photometric_stereo
from rti_rig.reconstruct.ptm import fit_ptm, reading_bias_deg


def one_side() -> np.ndarray:
    """18 lights on one side: azimuth 0-90° (6) at 20°, 45° and 70° elevation."""
    az = np.tile(np.linspace(0.0, 90.0, 6), 3)
    return direction_from_az_el(az, np.repeat([20.0, 45.0, 70.0], 6))


LIGHT_SETS = {
    "one side, 18": one_side,
    "ring at 35°, 12": lambda: rings(((35, 12, 0),)),
    "ring at 20°, 16": lambda: rings(((20, 16, 0),)),
    # well conditioned, read off by reading_bias_deg: the dome below 30° and other low bands
    "rings at 10°/25°, 16": lambda: rings(((10, 8, 0), (25, 8, 15))),
    "rings at 15°/30°, 24": lambda: rings(((15, 12, 0), (30, 12, 15))),
    "rings at 10°/40°, 6": lambda: rings(((10, 3, 0), (40, 3, 60))),
    "rings at 15°/45°, 9": lambda: rings(((15, 5, 0), (45, 4, 20))),
    # below the limit, the PTM kept: robust PS was 44° off on the coin here
    "rings at 15°/40°/70°, 7": lambda: rings(((15, 4, 0), (40, 2, 20), (70, 1, 0))),
}


def row(scene: str, name: str, seed: int = 0) -> str:
    """One table row: the PTM's, robust PS's and Lambert's normal errors (mean °)."""
    lights = LIGHT_SETS[name]()
    images, truth = render(scene, lights, seed)
    ptm = fit_ptm(images, lights)
    robust = fit_photometric_stereo(images, lights, robust=True)
    ls = fit_photometric_stereo(images, lights, robust=False)
    e = [angles(m.normals(), truth).mean() for m in (ptm,)]
    e += [angles(m.normals, truth).mean() for m in (robust, ls)]
    better = "either" if abs(e[1] - e[2]) < 0.05 else "robust PS" if e[1] < e[2] else "Lambert"
    source, _ = conditioned_normal_source("ptm", lights)
    used = {"ptm": "the PTM", "ps-robust": "robust PS", "": "none"}[source]
    bias = f"{reading_bias_deg(lights):.1f}" if source else "-"
    return (
        f"| {scene} | {name} | {bias} | {e[0]:.1f} | {e[1]:.2f} | {e[2]:.2f} | {better} | {used} |"
    )


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--write", action="store_true", help="write the table into docs/")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rows = [row(scene, name) for scene in SCENES for name in LIGHT_SETS]
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.ptm_normals_fallback --write` "
            f"({time.perf_counter() - t0:.0f} s). {machine_line()} Simulated scenes "
            f"{SIZE[0]}×{SIZE[1]} px; mean angle to the true normals.",
            "",
            "| scene | lights | reading bias on these lights (°) | the PTM's reading (°) | "
            "robust PS (°) | least-squares Lambert (°) | better here | `fit --model ptm` uses |",
            "|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section("ptm_normals_fallback", md, DOC)
    return md


if __name__ == "__main__":
    main()
