"""The simulator's picture for the docs: scenes under a few lights, next to their normal maps.

python -m benchmarks.simulator_figure   # writes docs/figures/simulator_scenes.png
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rti_rig.geometry import direction_from_az_el
from simulator.camera_model import CameraModel, to_srgb8
from simulator.light_transport import light_at, render_radiance
from simulator.scenes import make_scene

OUT = Path(__file__).resolve().parent.parent / "docs" / "figures" / "simulator_scenes.png"
LIGHTS = ((0.0, 15.0), (135.0, 35.0), (250.0, 60.0))


def main() -> None:
    scenes = ("coin", "tablet", "painting", "industrial")
    cam = CameraModel()
    exposure = cam.exposure_for(1.0, 0.8)
    fig, axes = plt.subplots(len(scenes), len(LIGHTS) + 1, figsize=(10, 2.6 * len(scenes)))
    rng = np.random.default_rng(0)
    for r, name in enumerate(scenes):
        scene = make_scene(name, 256, 256, seed=1)
        for c, (az, el) in enumerate(LIGHTS):
            light = light_at(direction_from_az_el(az, el), 400.0)
            pixels, white = cam.expose(render_radiance(scene, light), exposure, rng)
            axes[r, c].imshow(to_srgb8(pixels, white))
            axes[r, c].set_title(f"{name}: az {az:g}°, el {el:g}°", fontsize=8)
        axes[r, -1].imshow(((scene.normals + 1.0) / 2.0).clip(0, 1))
        axes[r, -1].set_title(f"{name}: normal map", fontsize=8)
    for ax in axes.ravel():
        ax.set_axis_off()
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=80)
    print(OUT)


if __name__ == "__main__":
    main()
