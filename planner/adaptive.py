"""Adaptive acquisition: the next light chosen from what the images captured so far show.

Pure functions, no fitting: the caller (``rti_rig.app.usecases.adaptive``) fits normals and
albedo to the images so far and passes a :class:`SurfaceState` — a sample of fitted pixels with
their normal, albedo, noise and, for each light already captured, whether that observation
really lit the pixel (not in shadow, not saturated). What one preview cannot show (the real
relief, shadows, gloss — as residual misfit) arrives with every image.

Model (the Cramér–Rao bound of the per-pixel Lambertian fit, algorithms notes §3): pixel ``p``
with normal ``n``, albedo ``ρ`` and noise ``σ`` has information ``M = Σ_k w_k l_k l_kᵀ`` over the
captured lights, ``w_k`` = 1 where observation k lit it, and expected squared angular error
``E[θ²] = (σ/ρ)² tr(P M⁻¹ P)``, ``P = I − n nᵀ`` (capped at 90°², an unobservable normal).
A candidate light ``l`` with predicted weight ``w`` (attached shadow from the fitted normal,
soft below :data:`GRAZING_COS`) updates ``M⁻¹`` by Sherman–Morrison, so the predicted error of
every candidate on every sampled pixel is one vectorised expression.

The next light is the available candidate with the largest predicted drop of the mean angular
error per second of rig time (capture plus, on an arm, the move from the current light: counted
as :func:`choose_next`'s ``move_s``); on a dome every light costs the same and this is the
largest drop. The error estimate the stopping rule uses is the bound's mean angle times a factor
calibrated against measured error on the simulator (:data:`ESTIMATE_SCALE`, docs/adaptive.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: Below this n·l a light is treated as (softly) shadowed for a pixel, as in the objectives.
GRAZING_COS = 0.15
#: Cap of the per-pixel squared angular error (rad²): an unobservable normal is "90° wrong".
MAX_ERR2 = (np.pi / 2) ** 2
#: Ridge added to each pixel's information matrix (fewer than 3 lit lights stay finite).
RIDGE = 1e-4
#: Calibrated factor from the bound's mean angle to the measured mean angular error: the
#: geometric mean of measured/raw over the simulator's five scenes, 8 draws each, N = 6…18
#: (``python -m benchmarks.adaptive``: 0.892; predicted against measured in docs/adaptive.md).
ESTIMATE_SCALE = 0.892
#: Lights of the starting layout (a homogeneous layout: robust, needs nothing known).
START_LIGHTS = 4
#: Elevation floor of the starting layout (no grazing light before anything is known).
START_FLOOR_DEG = 20.0


@dataclass(frozen=True)
class SurfaceState:
    """What is known of the surface after the images so far (a pixel sample).

    ``normals`` (P, 3) unit, ``albedo`` (P,), ``noise`` (P,) per-observation noise in the
    images' units (sensor noise and Lambertian misfit), ``lit`` (P, K) whether each of the K
    captured lights ``lights`` (K, 3) really lit the pixel.
    """

    normals: NDArray[np.float64]
    albedo: NDArray[np.float64]
    noise: NDArray[np.float64]
    lit: NDArray[np.bool_]
    lights: NDArray[np.float64]


@dataclass(frozen=True)
class Decision:
    """One adaptive choice and its evidence (recorded in the journal and the manifest)."""

    candidate: int | None  # index into the candidates; None: stop
    estimated_error_deg: float  # calibrated estimate of the mean normal error now
    predicted_error_deg: float | None  # the same estimate after the chosen light
    runner_up: list[dict[str, float]]  # the best few candidates: index, predicted, move_s
    reason: str

    def evidence(self) -> dict[str, object]:
        return {
            "candidate": self.candidate,
            "estimated_error_deg": round(self.estimated_error_deg, 4),
            "predicted_error_deg": (
                None if self.predicted_error_deg is None else round(self.predicted_error_deg, 4)
            ),
            "best_candidates": self.runner_up,
            "reason": self.reason,
        }


def _inverse_information(state: SurfaceState) -> NDArray[np.float64]:
    """Per pixel ``(M + ridge I)⁻¹`` (P, 3, 3) from the lights that really lit it."""
    w = state.lit.astype(np.float64)  # (P, K)
    outer = (state.lights[:, :, None] * state.lights[:, None, :]).reshape(-1, 9)  # (K, 9)
    m = (w @ outer).reshape(-1, 3, 3) + RIDGE * np.eye(3)
    return np.linalg.inv(m)


def _tangent_trace(minv: NDArray[np.float64], n: NDArray[np.float64]) -> NDArray[np.float64]:
    """``tr(P M⁻¹ P) = tr(M⁻¹) − nᵀ M⁻¹ n`` per pixel."""
    return np.trace(minv, axis1=1, axis2=2) - np.einsum("pi,pij,pj->p", n, minv, n)


def _scale2(state: SurfaceState) -> NDArray[np.float64]:
    """(σ/ρ)² per pixel (a dark pixel is as uncertain as its albedo is low)."""
    rho = np.maximum(state.albedo, 1e-6)
    return (state.noise / rho) ** 2


def mean_error_deg(err2: NDArray[np.float64]) -> float:
    """Mean angle (°) of per-pixel squared errors (rad²), each capped at 90°."""
    return float(np.degrees(np.sqrt(np.minimum(err2, MAX_ERR2))).mean())


def bound_error2(state: SurfaceState) -> NDArray[np.float64]:
    """Per-pixel expected squared angular error (rad²) with the lights captured so far."""
    return np.minimum(
        _scale2(state) * _tangent_trace(_inverse_information(state), state.normals), MAX_ERR2
    )


def estimate_error_deg(state: SurfaceState, scale: float = ESTIMATE_SCALE) -> float:
    """The calibrated estimate of the mean normal error (°) now."""
    return scale * mean_error_deg(bound_error2(state))


def predicted_error2(state: SurfaceState, candidates: NDArray[np.float64]) -> NDArray:
    """Per pixel and candidate (P, C): the squared error after adding that light."""
    minv = _inverse_information(state)
    n = state.normals
    t = _tangent_trace(minv, n)  # (P,)
    # single precision for the (P, 3, C) scan: it ranks candidates, and halves memory traffic
    minv, n = minv.astype(np.float32), n.astype(np.float32)
    lt = np.ascontiguousarray(candidates.T, dtype=np.float32)  # (3, C)
    cos = n @ lt  # (P, C)
    w = np.clip(cos / GRAZING_COS, 0.0, 1.0)  # attached shadow, soft at grazing light
    p = len(n)
    u = (minv.reshape(p * 3, 3) @ lt).reshape(p, 3, -1)  # M⁻¹ l, (P, 3, C): one product
    lu = (u * lt).sum(axis=1)
    uu = (u * u).sum(axis=1)
    nu = (u * n[:, :, None]).sum(axis=1)
    drop = w * (uu - nu * nu) / (1.0 + w * lu)
    return np.minimum(_scale2(state)[:, None] * np.maximum(t[:, None] - drop, 0.0), MAX_ERR2)


def choose_next(
    state: SurfaceState,
    candidates: NDArray[np.float64],
    available: NDArray[np.bool_],
    *,
    capture_s: float = 1.0,
    move_s: NDArray[np.float64] | None = None,
    scale: float = ESTIMATE_SCALE,
    keep: int = 3,
) -> Decision:
    """The available candidate with the largest predicted error drop per second of rig time.

    ``move_s`` (C,): time to bring the light there from where it is (an arm); None: a dome.
    Ties go to the lower candidate index, so a decision is a deterministic function of its
    inputs (``--resume`` repeats it).
    """
    now = scale * mean_error_deg(bound_error2(state))
    idx = np.flatnonzero(available)
    if idx.size == 0:
        return Decision(None, now, None, [], "no candidate light left")
    err2 = predicted_error2(state, candidates[idx])
    after = scale * np.degrees(np.sqrt(err2)).mean(axis=0)  # (C',)
    moves = np.zeros(idx.size) if move_s is None else np.asarray(move_s, float)[idx]
    gain = (now - after) / (capture_s + moves)
    order = np.lexsort((idx, -np.round(gain, 12)))  # best gain first, then lower index
    best = order[0]
    runner = [
        {
            "candidate": int(idx[j]),
            "predicted_error_deg": round(float(after[j]), 4),
            "move_s": round(float(moves[j]), 3),
        }
        for j in order[:keep]
    ]
    return Decision(
        int(idx[best]),
        now,
        float(after[best]),
        runner,
        "largest predicted drop of the mean normal error per second of rig time",
    )
