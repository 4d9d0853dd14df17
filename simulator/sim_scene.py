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


@dataclass(frozen=True, eq=False)
class HeightFieldScene:
    """Ground truth of a scene: height in pixel units, unit normals (frame of DESIGN.md), albedo."""

    name: str
    height: NDArray[np.float64]
    normals: NDArray[np.float64]
    albedo: NDArray[np.float64]


def normals_from_height(height: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit normals of a height field with unit pixel pitch; y is up, so rows are flipped."""
    dh_drow, dh_dcol = np.gradient(height)
    dh_dx = dh_dcol
    dh_dy = -dh_drow  # frame y runs towards row 0
    n = np.stack([-dh_dx, -dh_dy, np.ones_like(height)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


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
