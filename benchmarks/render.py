"""Renderer speed and memory at 1 megapixel, 100 lights, shadows + specular; and the docs figure.

Run: ``python -m benchmarks.render`` (figures to docs/benchmarks.md, section "render") and
``python -m benchmarks.render --figure`` (docs/figures/sim_scenes.png).
"""

from __future__ import annotations

import argparse
import statistics
import time
import tracemalloc
from pathlib import Path

import numpy as np

from benchmarks.report import machine_line, write_section
from rti_rig.simulator import light_transport as lt
from rti_rig.simulator.ground_truth import homogeneous_directions
from rti_rig.simulator.light_transport import light_at, prepare, render_radiance
from rti_rig.simulator.scenes import make_scene

FIGURE = Path(__file__).resolve().parent.parent / "docs" / "figures" / "sim_scenes.png"


def _time_lights(fn, lights) -> list[float]:
    out = []
    for light in lights:
        t0 = time.perf_counter()
        fn(light)
        out.append(time.perf_counter() - t0)
    return out


def run(size: int = 1000, n_lights: int = 100, dome_mm: float = 400.0) -> str:
    scene = make_scene("coin", size, size, seed=0)
    prep = prepare(scene)
    mp = size * size / 1e6
    dirs = homogeneous_directions(n_lights, min_elevation_deg=10.0)
    rows = []
    for label, dist in (("point lights (dome 400 mm)", dome_mm), ("directional lights", None)):
        lights = [light_at(d, dist) for d in dirs]
        tracemalloc.start()
        total = _time_lights(lambda lg: render_radiance(scene, lg), lights)
        peak = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.stop()
        diffuse = _time_lights(lambda lg: render_radiance(scene, lg, passes=()), lights)
        shadows = _time_lights(lambda lg: lt.visibility(prep, lg), lights)
        spec = _time_lights(lambda lg: render_radiance(scene, lg, passes={"specular"}), lights)
        med = statistics.median
        rows.append(
            f"| {label} | {med(total):.3f} | {med(total) / mp:.3f} | {med(diffuse):.3f} | "
            f"{med(shadows):.3f} | {med(spec) - med(diffuse):.3f} | {peak:.0f} |"
        )
        print(rows[-1])
    md = (
        f"Coin scene {size}x{size} ({mp:.1f} MP) with shadows and GGX specular, {n_lights} "
        "homogeneous lights (elevation >= 10°), medians per light; memory peak = tracemalloc "
        "peak of numpy allocations during the full renders (scene arrays excluded).\n"
        f"Command: `python -m benchmarks.render`. {machine_line()}\n\n"
        "| lights | s / light | s / MP-light | diffuse only (s) | shadow pass (s) | "
        "specular pass (s) | peak MB |\n|---|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n"
    )
    write_section("render", md)
    return md


def figure(size: int = 384) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rti_rig.core.geometry import direction_from_az_el
    from rti_rig.simulator.camera_model import CameraModel, to_srgb8

    cam, rng = CameraModel(), np.random.default_rng(0)
    lights = [(0, 15), (120, 35), (240, 60), (0, 90)]
    names = ("coin", "tablet", "painting")
    fig, ax = plt.subplots(len(names), 5, figsize=(15, 3.1 * len(names)))
    for i, name in enumerate(names):
        scene = make_scene(name, size, size, seed=1)
        for j, (az, el) in enumerate(lights):
            img = render_radiance(scene, light_at(direction_from_az_el(az, el), 400.0))
            px, white = cam.expose(img, cam.exposure_for(1.0, 0.8), rng)
            ax[i, j].imshow(to_srgb8(px, white))
            ax[i, j].set_title(f"{name}: az {az}°, el {el}°", fontsize=9)
        ax[i, 4].imshow((scene.normals + 1) / 2)
        ax[i, 4].set_title(f"{name}: normal map (x→R, y↑→G)", fontsize=9)
        for a in ax[i]:
            a.axis("off")
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=70)
    return FIGURE


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--figure", action="store_true", help="only write the docs figure")
    parser.add_argument("--size", type=int, default=1000)
    parser.add_argument("--lights", type=int, default=100)
    parser.add_argument(
        "--write", action="store_true", help="write the figures into docs/ (else print only)"
    )
    args = parser.parse_args()
    if args.figure:
        print(figure())
    else:
        print(run(args.size, args.lights))


if __name__ == "__main__":
    main()
