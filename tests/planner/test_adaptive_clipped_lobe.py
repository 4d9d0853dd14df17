"""Clipped observations read as lower bounds (planner.adaptive_bias.CLIPPED_CENSORED, a
benchmark variant): the lobe fitted to them reaches white where the camera clipped, where a
fit that takes white for a measured value stays below it."""

from __future__ import annotations

import numpy as np
import pytest

import rti_rig.planner.adaptive_bias as bias
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner.adaptive_bias import fit_censored_lobe, fit_object_model


def _glossy(ks: float, e: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(observations clipped at white (K, P), lights, normals) of a glossy surface."""
    rng = np.random.default_rng(3)
    n = rng.normal(size=(1500, 3)) * [0.3, 0.3, 1.0]
    n[:, 2] = np.abs(n[:, 2]) + 0.5
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    lights = fibonacci_cap(24, 10.0, 85.0)
    h = lights + np.array([0.0, 0.0, 1.0])
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    cos = n @ lights.T
    clean = 0.4 * np.maximum(cos, 0) + ks * np.clip(n @ h.T, 0, 1) ** e * (cos > 0)
    return np.minimum(clean, 1.0).T, lights, n


def test_bounds_the_lobe_has_to_reach_raise_it_and_bounds_it_passes_cost_nothing() -> None:
    x = np.linspace(0.1, 1.0, 50)
    r = 2.0 * x
    # no bounds: ordinary least squares
    ks, cost = fit_censored_lobe(r, x, np.empty(0), np.empty(0))
    assert ks == pytest.approx(2.0) and cost == pytest.approx(0.0, abs=1e-12)
    # bounds the lobe already passes: nothing changes
    ks, cost = fit_censored_lobe(r, x, np.array([0.5]), np.array([1.0]))
    assert ks == pytest.approx(2.0) and cost == pytest.approx(0.0, abs=1e-12)
    # a bound above the lobe: the fit rises towards it, at the price of the measured residuals
    ks, cost = fit_censored_lobe(r, x, np.array([4.0] * 10), np.array([1.0] * 10))
    assert 2.0 < ks < 4.0 and cost > 0
    # never negative
    ks, _ = fit_censored_lobe(-r, x, np.empty(0), np.empty(0))
    assert ks == 0.0


@pytest.mark.parametrize("censored", [False, True])
def test_a_clipped_highlight_is_fitted_as_at_least_white_only_when_read_as_a_bound(
    monkeypatch: pytest.MonkeyPatch, censored: bool
) -> None:
    obs, lights, n = _glossy(ks=3.0, e=32.0)
    assert (obs >= 1.0).mean() > 0.005  # the highlights are clipped
    monkeypatch.setattr(bias, "CLIPPED_CENSORED", censored)
    m = fit_object_model(obs, lights, n, np.full(len(n), 0.4), np.ones(len(n), bool), 0.01, 0.002)
    half = lights + np.array([0.0, 0.0, 1.0])
    hc = np.clip(n @ (half / np.linalg.norm(half, axis=1, keepdims=True)).T, 0, 1)
    rendered = 0.4 * np.maximum(n @ lights.T, 0) + m.spec_strength * hc**m.spec_exponent
    clipped = obs.T >= 1.0
    # how far the model's rendering falls short of white where the camera clipped
    short = float(np.mean(np.maximum(0.0, 1.0 - rendered[clipped])))
    if censored:
        assert short < 0.02
        assert (m.spec_strength, m.spec_exponent) == (pytest.approx(3.0, rel=0.05), 32.0)
    else:  # white taken for a value: a lobe of a third the strength, broader, short of white
        assert short > 0.05
        assert m.spec_strength < 1.5 and m.spec_exponent < 32.0
