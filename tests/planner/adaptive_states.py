"""Test surfaces for the adaptive planner's tests (shared by its test files)."""

from __future__ import annotations

import numpy as np

from rti_rig.planner.adaptive import SurfaceState
from rti_rig.planner.adaptive_bias import ObjectModel


def state_for(normals: np.ndarray, lights: np.ndarray, noise: float = 0.01) -> SurfaceState:
    """A Lambertian surface of unit albedo: a light lights a pixel when n·l > 0."""
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    lit = normals @ lights.T > 0
    p = len(normals)
    return SurfaceState(normals, np.ones(p), np.full(p, noise), lit, lights)


def open_model(seed: int = 0, p: int = 300, spec: float = 0.0) -> ObjectModel:
    """An object model of ``p`` pixels facing the camera within ~40°, albedo 0.3–0.8, 0.4 %
    noise, a Blinn–Phong lobe of strength ``spec`` (exponent 32), and no cast shadows."""
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(p, 3)) * [0.4, 0.4, 1.0]
    n[:, 2] = np.abs(n[:, 2]) + 0.5
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return ObjectModel(
        normals=n,
        albedo=rng.uniform(0.3, 0.8, p),
        spec_strength=spec,
        spec_exponent=32.0,
        noise=0.004,
        shadow_el=np.full((p, 1), -np.inf),
        shadow_az=np.zeros((p, 1)),
        lights=np.zeros((0, 3)),
        shadowed=np.zeros((p, 0), dtype=bool),
    )
