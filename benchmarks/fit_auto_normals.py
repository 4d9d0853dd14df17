"""Where an auto fit's normals should come from: robust PS against least squares, sparse layouts.

`rti-rig fit --model auto` chooses a relighting model and reads the normal maps from it when
it is Lambert or the PTM (else from robust photometric stereo). At 7–12 lights it often chooses
Lambert, on matte and on glossy objects alike. This measures, on the simulator's scenes (the
renderer the fit tests use: shadows and each scene's specular lobe, 16-bit-like noise of 0.2 %
of the 0.8 white level), the mean normal error against the scene's true normals of robust PS
and of the least-squares Lambert fit, at three sparse ring layouts (15°/40°/70°), beside the
model `auto` chooses there: which estimator an auto fit should use is read off it.

Run: ``python -m benchmarks.fit_auto_normals [--write]`` (``--write`` replaces the section
``fit_auto_normals`` of docs/reconstruction.md).
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from benchmarks.report import machine_line, write_section
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct import fit_photometric_stereo
from rti_rig.reconstruct.model_select import select_model
from rti_rig.simulator.light_transport import DirectionalLight, render_radiance
from rti_rig.simulator.scenes import make_scene

DOC = Path(__file__).resolve().parent.parent / "docs" / "reconstruction.md"
SCENES = ("painting", "tablet", "tilted", "coin", "industrial")
#: rings of (elevation °, count, azimuth offset °): 7, 9 and 12 lights
LAYOUTS = {
    7: ((15, 4, 0), (40, 2, 20), (70, 1, 0)),
    9: ((15, 5, 0), (40, 3, 20), (70, 1, 0)),
    12: ((15, 6, 0), (40, 4, 20), (70, 2, 0)),
}
SIZE = (96, 112)
NOISE = 0.002


def rings(spec: tuple[tuple[float, int, float], ...]) -> np.ndarray:
    """Unit light directions of the rings (the project's frame, as a dome config's rings)."""
    return np.concatenate(
        [
            direction_from_az_el(off + 360.0 * np.arange(count) / count, np.full(count, el))
            for el, count, off in spec
        ]
    )


def angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.degrees(np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)))


def render(scene: str, lights: np.ndarray, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(images (N, H, W[, C]) float32 with the noise, true normals) of a simulated scene."""
    sc = make_scene(scene, SIZE[0], SIZE[1], seed=seed)
    images = np.stack([render_radiance(sc, DirectionalLight(tuple(d))) for d in lights])
    rng = np.random.default_rng(seed)
    images = images / np.percentile(images, 99.5) * 0.8
    images = np.clip(images + rng.normal(0.0, NOISE, images.shape), 0.0, 1.0).astype(np.float32)
    return images, np.asarray(sc.normals)


def row(scene: str, n: int, seed: int = 0) -> str:
    """One table row: auto's model, robust PS and least-squares errors (mean °)."""
    lights = rings(LAYOUTS[n])
    images, truth = render(scene, lights, seed)
    chosen = select_model(images, lights).model
    robust = fit_photometric_stereo(images, lights, robust=True)
    ls = fit_photometric_stereo(images, lights, robust=False)
    e_r, e_l = angles(robust.normals, truth).mean(), angles(ls.normals, truth).mean()
    three = float(np.mean(robust.used_lights == 3))
    used = "least squares" if chosen in ("lambert", "ptm") else "robust PS"
    better = "robust PS" if e_r < e_l else "least squares"
    return f"| {scene} | {n} | {chosen} | {e_r:.2f} | {e_l:.2f} | {three:.0%} | {used} | {better} |"


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rows = [row(scene, n) for scene in SCENES for n in LAYOUTS]
    md = "\n".join(
        [
            f"Command: `python -m benchmarks.fit_auto_normals --write` "
            f"({time.perf_counter() - t0:.0f} s). {machine_line()} Simulated scenes "
            f"{SIZE[0]}×{SIZE[1]} px, rings at 15°/40°/70°; mean angle to the true normals.",
            "",
            "| scene | lights | auto's model | robust PS (°) | least-squares Lambert (°) | "
            "pixels robust PS fits from 3 observations | an auto fit's normals | better here |",
            "|---|---|---|---|---|---|---|---|",
            *rows,
        ]
    )
    print(md)
    if args.write:
        write_section("fit_auto_normals", md, DOC)
    return md


if __name__ == "__main__":
    main()
