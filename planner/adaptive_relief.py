"""The relief's depth, fitted to the cast shadows the captured images show.

Why: the relief the bias-aware score marches cast shadows over (:mod:`rti_rig.planner.
adaptive_bias`) is integrated from fitted normals, and normals are slopes over a pixel or two:
an impression narrower than that (the simulator's clay tablet: wedges 0.1–0.5 px deep at
96 px) comes out shallower than it is, so its shadows under low light are under-predicted and
the score does not see the harm a low light does (with the scene's true height map the same
score ranks the floors the other way). The shadows themselves are in the images: each captured
light that faced a pixel but left it darker than the Lambertian fit says how deep the relief
around it is. So the relief's detail (the height with its best-fitting plane removed: a tilted
object is not made steeper) is scaled by the gain, among :data:`RELIEF_GAINS`, whose marched
shadows best explain the captured observations — a fit to this object's own images, no
constant tuned on a scene.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: Gains tried on the relief's detail (1: as integrated from the normals).
RELIEF_GAINS = (1.0, 1.5, 2.0, 3.0, 4.0)
#: Sampled pixels the gain is fitted on (every k-th of the chooser's sample: the march costs
#: pixels × lights × gains, inside every decision).
GAIN_PIXELS = 500
#: Below this n·l an observation says nothing of cast shadows (as the model's FACING_COS).
FACING_COS = 0.15


def detrended(height: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(plane, detail): the least-squares plane of ``height`` and what rises above it."""
    h = np.asarray(height, dtype=np.float64)
    rows, cols = np.indices(h.shape)
    a = np.stack([np.ones(h.size), cols.ravel(), rows.ravel()], axis=1)
    coef, *_ = np.linalg.lstsq(a, h.ravel(), rcond=None)
    plane = (a @ coef).reshape(h.shape)
    return plane, h - plane


def fit_relief_gain(
    height: NDArray[np.float64],
    rows: NDArray[np.intp],
    cols: NDArray[np.intp],
    obs: NDArray,
    lights: NDArray[np.float64],
    normals: NDArray[np.float64],
    albedo: NDArray[np.float64],
    valid: NDArray[np.bool_],
    gains: tuple[float, ...] = RELIEF_GAINS,
) -> tuple[float, NDArray[np.float64]]:
    """(gain, scaled height): the gain of the relief's detail whose marched cast shadows best
    explain the K × P captured observations ``obs`` of the sampled pixels (rows, cols) under
    the Lambertian fit (normals, albedo): least absolute deviation over the observations whose
    light faced their pixel (a highlight is the same under every gain and weighs least in L1).
    Ties go to the smaller gain (the relief as integrated, unless the shadows say otherwise)."""
    from rti_rig.planner.adaptive_bias import soft_visibility

    sel = np.arange(0, len(rows), max(1, len(rows) // GAIN_PIXELS))[:GAIN_PIXELS]
    rows, cols, normals, albedo, valid = rows[sel], cols[sel], normals[sel], albedo[sel], valid[sel]
    obs = np.asarray(obs, dtype=np.float64)[:, sel]
    cos = (normals @ lights.T).T  # (K, P)
    lam = albedo[None, :] * np.maximum(cos, 0.0)
    use = (cos > FACING_COS) & valid[None, :]
    if not use.any():
        return 1.0, np.asarray(height, dtype=np.float64)
    plane, detail = detrended(height)
    best = (np.inf, 1.0, np.asarray(height, dtype=np.float64))
    for g in gains:
        h = plane + g * detail
        vis = soft_visibility(h, rows, cols, lights).T  # (K, P)
        cost = float(np.abs(obs - lam * vis)[use].sum())
        if cost < best[0] * (1.0 - 1e-9):
            best = (cost, g, h)
    return best[1], best[2]
