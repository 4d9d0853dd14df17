"""A Lambertian test surface for the adaptive planner's tests (shared by its test files)."""

from __future__ import annotations

import numpy as np

from rti_rig.planner.adaptive import SurfaceState


def state_for(normals: np.ndarray, lights: np.ndarray, noise: float = 0.01) -> SurfaceState:
    """A Lambertian surface of unit albedo: a light lights a pixel when n·l > 0."""
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    lit = normals @ lights.T > 0
    p = len(normals)
    return SurfaceState(normals, np.ones(p), np.full(p, noise), lit, lights)
