"""The relief's depth fitted to the captured cast shadows (planner/adaptive_relief.py): the
gain whose marched shadows explain the observations is recovered, a relief already right keeps
gain 1, a tilted object is not made steeper, and the object model uses the fitted relief only
when asked (off in what ships)."""

from __future__ import annotations

import numpy as np
import pytest

import rti_rig.planner.adaptive_bias as bias
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner.adaptive_bias import fit_object_model, soft_visibility
from rti_rig.planner.adaptive_relief import detrended, fit_relief_gain

SIZE = 64


def _grooves(depth: float) -> np.ndarray:
    """A flat plate with narrow grooves (pixels) — what casts shadows under low light."""
    h = np.zeros((SIZE, SIZE))
    for c in range(6, SIZE - 6, 7):  # a period the fit's every-k-th pixel sample does not skip
        h[:, c : c + 2] -= depth
    return h


def _sample() -> tuple[np.ndarray, np.ndarray]:
    rows, cols = np.indices((SIZE, SIZE))
    return rows.ravel(), cols.ravel()


def _observe(true_height: np.ndarray, lights: np.ndarray) -> np.ndarray:
    """Lambertian observations of a level plate (albedo 0.5) shadowed by ``true_height``."""
    rows, cols = _sample()
    vis = soft_visibility(true_height, rows, cols, lights)  # (P, K)
    return (0.5 * lights[:, 2][None, :] * vis).T  # (K, P)


def _fit(integrated: np.ndarray, obs: np.ndarray, lights: np.ndarray) -> tuple[float, np.ndarray]:
    rows, cols = _sample()
    p = len(rows)
    normals = np.tile([0.0, 0.0, 1.0], (p, 1))
    return fit_relief_gain(
        integrated, rows, cols, obs, lights, normals, np.full(p, 0.5), np.ones(p, dtype=bool)
    )


LIGHTS = fibonacci_cap(8, 12.0, 60.0)


def test_a_shallow_relief_is_deepened_to_the_shadows_seen() -> None:
    truth = _grooves(1.0)
    integrated = _grooves(0.5)  # rounded off: half as deep as the shadows say
    gain, height = _fit(integrated, _observe(truth, LIGHTS), LIGHTS)
    assert gain == 2.0
    np.testing.assert_allclose(detrended(height)[1], detrended(truth)[1], atol=1e-9)


def test_a_relief_that_explains_the_shadows_keeps_gain_one() -> None:
    truth = _grooves(1.0)
    gain, height = _fit(truth, _observe(truth, LIGHTS), LIGHTS)
    assert gain == 1.0
    np.testing.assert_allclose(height, truth)


def test_a_tilted_object_is_not_made_steeper() -> None:
    rows, cols = np.indices((SIZE, SIZE))
    plane = 0.1 * cols - 0.05 * rows  # gentler than the lowest light: it shadows nothing
    integrated = plane + _grooves(0.5)
    gain, height = _fit(integrated, _observe(plane + _grooves(1.0), LIGHTS), LIGHTS)
    assert gain == 2.0
    # the tilt is the one integrated: only the detail is deepened
    np.testing.assert_allclose(detrended(height)[0], detrended(integrated)[0], atol=1e-9)


@pytest.mark.parametrize("enabled", [False, True])
def test_the_object_model_fits_the_gain_only_when_asked(
    monkeypatch: pytest.MonkeyPatch, enabled: bool
) -> None:
    monkeypatch.setattr(bias, "FIT_RELIEF_GAIN", enabled)
    truth, integrated = _grooves(1.0), _grooves(0.5)
    obs = _observe(truth, LIGHTS)
    rows, cols = _sample()
    p = len(rows)
    n = np.tile([0.0, 0.0, 1.0], (p, 1))
    m = fit_object_model(
        obs, LIGHTS, n, np.full(p, 0.5), np.ones(p, bool), 0.01, 0.002, (integrated, rows, cols)
    )
    assert m.relief is not None
    if enabled:
        assert m.relief_gain == 2.0
        np.testing.assert_allclose(m.relief[0], detrended(truth)[1] + detrended(integrated)[0])
    else:
        assert m.relief_gain == 1.0
        assert m.relief[0] is integrated
