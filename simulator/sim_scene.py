"""A small height-field scene for the walking skeleton's simulated camera.

A central hemispherical boss, a few seeded bumps and an engraved ring on a flat ground, with a
patchy colour albedo. It is enough for the brightest region to follow the light, which is what a
dry run and the skeleton's tests need; the full scene library and light transport (shadows,
specular, point lights) live in the renderer modules.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.simulator.scenes import normals_from_height


@dataclass(frozen=True, eq=False)
class HeightFieldScene:
    """Ground truth: height in pixel units, unit normals (frame: docs/conventions.md), albedo."""

    name: str
    height: NDArray[np.float64]
    normals: NDArray[np.float64]
    albedo: NDArray[np.float64]


def relief_scene(height_px: int, width_px: int, seed: int = 0) -> HeightFieldScene:
    """The skeleton's default scene (see the module docstring)."""
    rng = np.random.default_rng(seed)
    rows, cols = np.mgrid[0:height_px, 0:width_px].astype(np.float64)
    cy, cx = (height_px - 1) / 2.0, (width_px - 1) / 2.0
    size = float(min(height_px, width_px))
    r = np.hypot(rows - cy, cols - cx)

    boss_r = 0.22 * size
    height = np.sqrt(np.clip(boss_r**2 - r**2, 0.0, None))
    for _ in range(6):
        by, bx = rng.uniform(0.1, 0.9, 2) * (height_px, width_px)
        s = rng.uniform(0.03, 0.06) * size
        height += rng.uniform(0.2, 0.5) * s * np.exp(-((rows - by) ** 2 + (cols - bx) ** 2) / s**2)
    ring_r, ring_w = 0.36 * size, 0.012 * size
    height -= 0.02 * size * np.exp(-(((r - ring_r) / ring_w) ** 2))

    base = rng.uniform(0.35, 0.85, size=(4, 4, 3))
    iy = np.minimum(np.arange(height_px) * 4 // height_px, 3)
    ix = np.minimum(np.arange(width_px) * 4 // width_px, 3)
    albedo = base[iy][:, ix]
    return HeightFieldScene("relief", height, normals_from_height(height), albedo)


def lambert_radiance(
    scene: HeightFieldScene, direction: NDArray[np.float64], irradiance: float = 1.0
) -> NDArray[np.float64]:
    """Radiance of a Lambertian surface under a directional light (attached shadows only)."""
    cos = np.clip(scene.normals @ np.asarray(direction, dtype=np.float64), 0.0, None)
    return scene.albedo * (irradiance * cos)[..., None]


def renderer_for(
    name: str,
    height_px: int,
    width_px: int,
    seed: int = 0,
    light_distance_mm: float | None = None,
):  # type: ignore[no-untyped-def]
    """``render(direction | None, intensity) -> (H, W, 3)`` radiance for a named scene.

    ``relief`` is this module's simple Lambertian scene; every other name is a scene of the
    library (:mod:`rti_rig.simulator.scenes`), rendered with the passes it needs (cast shadows, GGX
    specular) under a directional light, or a point lamp at ``light_distance_mm`` (the dome's
    radius or the arm's reach) when given. The simulated camera and the wrong-light check both
    render through this one function, so they cannot disagree about what a light looks like.
    """
    if name == "relief":
        scene = relief_scene(height_px, width_px, seed)

        def render_relief(direction, intensity):  # type: ignore[no-untyped-def]
            if direction is None:
                return np.zeros_like(scene.albedo)
            return lambert_radiance(scene, direction, intensity)

        return render_relief

    from rti_rig.simulator.light_transport import light_at, render_radiance
    from rti_rig.simulator.scenes import make_scene

    library = make_scene(name, height_px, width_px, seed=seed)

    def render(direction, intensity):  # type: ignore[no-untyped-def]
        if direction is None or intensity <= 0:
            return np.zeros(library.albedo.shape, dtype=np.float64)
        light = light_at(direction, light_distance_mm, irradiance=float(intensity))
        return render_radiance(library, light).astype(np.float64)

    return render
