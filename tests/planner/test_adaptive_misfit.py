"""The stop's misfit bound (``planner.adaptive_until.misfit_deg``) and its place in the upper
estimate: the larger of the simulated term and the bound, plus the unsolved term."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.app.usecases.adaptive import fit_sample
from rti_rig.planner.adaptive_until import (
    UPPER_FACTOR,
    misfit_decides,
    misfit_deg,
    reaches_target,
    upper_error_deg,
)


def _lights(k: int, low: float = 20.0, high: float = 70.0) -> np.ndarray:
    """``k`` unit lights on a spiral between ``low`` and ``high`` degrees of elevation."""
    el = np.radians(np.linspace(low, high, k))
    az = np.radians(np.arange(k) * 137.5)
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], 1)


def _surface(p: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    tilt = np.radians(rng.uniform(0, 30, p))
    az = rng.uniform(0, 2 * np.pi, p)
    normals = np.stack([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), np.cos(tilt)], 1)
    return normals, rng.uniform(0.4, 0.8, p)


def _render(normals: np.ndarray, albedo: np.ndarray, lights: np.ndarray, noise: float, seed: int):
    clean = np.maximum(lights @ normals.T, 0.0) * albedo  # (K, P)
    rng = np.random.default_rng(seed)
    return (clean + noise * rng.standard_normal(clean.shape)).astype(np.float32)


def _bound(obs: np.ndarray, lights: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    state = fit_sample(obs, lights)
    assert state is not None
    bound = misfit_deg(
        state.residual, state.used, state.albedo, state.valid, state.lit, state.lights
    )
    assert bound is not None
    return bound, state.normals, state.valid


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.degrees(np.arccos(np.clip(np.sum(a * b, 1), -1.0, 1.0)))


def test_the_upper_estimate_is_the_larger_term_plus_the_unsolved_one() -> None:
    assert upper_error_deg(1.0, 2.0, 0.0, 90.0, misfit=None) == pytest.approx(2.0)
    assert upper_error_deg(1.0, 2.0, 0.0, 90.0, misfit=1.5) == pytest.approx(2.0)
    assert upper_error_deg(1.0, 2.0, 0.0, 90.0, misfit=3.0) == pytest.approx(3.0)
    assert upper_error_deg(1.0, 2.0, 0.01, 90.0, misfit=3.0) == pytest.approx(3.9)
    assert misfit_decides(1.0, 2.0, 3.0) and not misfit_decides(1.0, 2.0, 1.5)
    assert not misfit_decides(1.0, 2.0, None)
    # the images can hold a claim back, never make one the simulation would not
    assert not reaches_target(1.0, 2.5, 2.0, misfit=3.0)
    assert not reaches_target(1.0, 1.9, 2.0, misfit=0.0)
    assert reaches_target(0.5, 1.0, UPPER_FACTOR, misfit=0.9)


def test_a_surface_the_fit_explains_has_a_bound_near_zero() -> None:
    """Noise alone is not misfit: the allowance for noise keeps the bound near zero where every
    pixel fits (without it, the bound had floored at the noise: 0.4–0.6° on the dome)."""
    normals, albedo = _surface(2000)
    lights = _lights(12)
    bound, _, _ = _bound(_render(normals, albedo, lights, 0.004, 1), lights)
    assert bound < 0.1, bound


def test_a_penumbra_the_fit_keeps_is_bounded_from_above() -> None:
    """A tenth of the pixels darkened by half in two lights (too bright to be dropped as a
    shadow): the fit keeps them and errs there; the bound stands above what the penumbra turned
    the normals by (the same images without it, fitted alike: the noise's share is not the
    bound's to count) and well above the clean surface's bound."""
    normals, albedo = _surface(2000, seed=2)
    lights = _lights(12)
    clean = _render(normals, albedo, lights, 0.004, 3)
    obs = clean.copy()
    hit = np.zeros(obs.shape[1], dtype=bool)
    hit[::10] = True
    for k in (1, 6):  # two lights' penumbra on those pixels
        obs[k, hit] *= 0.5
    bound, fitted, valid = _bound(obs, lights)
    clean_bound, unshadowed, clean_valid = _bound(clean, lights)
    both = valid & clean_valid
    turned = np.where(both, _angles(fitted, unshadowed), 0.0)
    assert turned[hit].mean() > 3.0  # the fit does keep them (else the test shows nothing)
    assert bound >= 1.3 * turned.mean(), (bound, turned.mean())
    assert bound > 5 * clean_bound, (bound, clean_bound)


def test_grazing_lights_from_one_side_weigh_a_misfit_more() -> None:
    """The same misfit costs more under lights that pin the normal weakly (a small smallest
    singular value), as a pixel on a wall lit only by grazing lights from one side."""
    spread = _lights(8)
    grazing = _lights(8, 5.0, 12.0)
    grazing[:, 0] = np.abs(grazing[:, 0])  # one side only
    grazing /= np.linalg.norm(grazing, axis=1, keepdims=True)
    # 4 misfit pixels among 100 whose residual is noise (the median: the noise scale)
    residual = np.concatenate([np.full(4, 0.02), np.full(96, 1e-4)])
    used, albedo = np.full(100, 8), np.full(100, 0.5)
    valid, kept = np.ones(100, dtype=bool), np.ones((100, 8), dtype=bool)
    wide = misfit_deg(residual, used, albedo, valid, kept, spread)
    low = misfit_deg(residual, used, albedo, valid, kept, grazing)
    assert wide is not None and low is not None
    assert low > 2 * wide > 0, (low, wide)


def test_no_residual_no_bound() -> None:
    """Three lights per pixel leave no residual: nothing to bound (None), not a bound of 0°."""
    five = np.ones(5, dtype=bool)
    bound = misfit_deg(
        np.zeros(5), np.full(5, 3), np.ones(5), five, np.ones((5, 3), bool), _lights(3)
    )
    assert bound is None
