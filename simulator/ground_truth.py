"""Dense reference acquisitions: the homogeneous many-light ground truth of the paper.

The paper this project grew from compares planned acquisitions with a dense acquisition of 500
homogeneously spaced light positions on the hemisphere. Here "homogeneous" is the Fibonacci
(golden-angle) spiral: equal-area in z (so equal solid angle per light) and evenly spread in
azimuth, deterministic, and defined for any n — unlike geodesic domes, which exist only for
special counts.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.geometry import fibonacci_cap
from rti_rig.simulator.light_transport import Light, light_at, render_radiance
from rti_rig.simulator.scenes import Scene, SceneError

#: Refuse to hold a ground truth larger than this in memory; use ``iter_ground_truth`` instead.
DEFAULT_MAX_BYTES = 2 * 1024**3


def homogeneous_directions(n: int, min_elevation_deg: float = 0.0) -> NDArray[np.float64]:
    """``n`` unit light directions (n, 3) evenly covering the hemisphere above ``min_elevation``.

    Fibonacci spiral: z_k = z_min + (1 - z_min)(k + ½)/n (equal solid angle per light),
    azimuth_k = k × golden angle. No light is exactly at the horizon or the zenith.
    """
    if not 0.0 <= min_elevation_deg < 90.0:
        raise ValueError(f"min_elevation_deg must be in [0, 90), got {min_elevation_deg}")
    try:
        return fibonacci_cap(int(n), min_elevation_deg, 90.0)
    except ValueError as exc:
        raise ValueError(f"homogeneous_directions: {exc}") from None


@dataclass(frozen=True, eq=False)
class GroundTruth:
    """A dense acquisition: ``images[k]`` (π × radiance, float32) under ``lights[k]``."""

    scene: Scene
    directions: NDArray[np.float64]  # (n, 3) nominal directions (towards the light)
    lights: tuple[Light, ...]
    images: NDArray[np.float32]  # (n, H, W, 3)

    @property
    def normals(self) -> NDArray[np.float64]:
        """The scene's true normals (H, W, 3)."""
        return self.scene.normals

    @property
    def albedo(self) -> NDArray[np.float64]:
        """The scene's true diffuse albedo (H, W, 3)."""
        return self.scene.albedo


def iter_ground_truth(
    scene: Scene,
    directions: NDArray[np.float64],
    *,
    distance_mm: float | None = None,
    passes: Iterable[str] | None = None,
) -> Iterator[tuple[Light, NDArray[np.float32]]]:
    """Yield (light, image) one light at a time: constant memory for large scenes."""
    for d in np.asarray(directions, dtype=np.float64).reshape(-1, 3):
        light = light_at(d, distance_mm)
        yield light, render_radiance(scene, light, passes)


def render_ground_truth(
    scene: Scene,
    n_lights: int = 500,
    *,
    distance_mm: float | None = None,
    min_elevation_deg: float = 0.0,
    passes: Iterable[str] | None = None,
    max_bytes: int = DEFAULT_MAX_BYTES,
) -> GroundTruth:
    """Render the ``n_lights`` homogeneous acquisition of ``scene`` (noise-free radiance).

    ``distance_mm=None`` uses directional lights; a distance renders point lamps on a dome of
    that radius, each as bright at the centre as a unit directional light.
    """
    rows, cols = scene.shape
    need = int(n_lights) * rows * cols * 3 * 4
    if need > max_bytes:
        raise SceneError(
            f"ground truth of '{scene.name}' ({n_lights} lights, {rows}x{cols}) needs "
            f"{need / 1e9:.1f} GB > max_bytes {max_bytes / 1e9:.1f} GB; render a smaller scene, "
            "raise max_bytes, or stream with iter_ground_truth()"
        )
    dirs = homogeneous_directions(n_lights, min_elevation_deg)
    images = np.empty((len(dirs), rows, cols, 3), dtype=np.float32)
    lights: list[Light] = []
    for k, (light, img) in enumerate(
        iter_ground_truth(scene, dirs, distance_mm=distance_mm, passes=passes)
    ):
        images[k] = img
        lights.append(light)
    images.flags.writeable = False
    return GroundTruth(scene=scene, directions=dirs, lights=tuple(lights), images=images)
