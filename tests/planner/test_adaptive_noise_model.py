"""The object model's signal-dependent noise (planner/adaptive_bias.py, ``fit_noise_model``).

A camera's noise is shot noise (variance ∝ signal, ~0 in the dark); the relighting score
averages per-light PSNRs, so one constant σ for every observation made a held-out light that
leaves the object dark as noisy as a bright one, and compressed the simulated ranking of the
layouts (docs/adaptive.md, "Signal-dependent noise in the object model")."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner import adaptive_bias
from rti_rig.planner.adaptive_bias import (
    fit_noise_model,
    fit_object_model,
    light_noise,
    standardized_residuals2,
)
from rti_rig.planner.adaptive_relight import mean_psnr_db

A_TRUE, B_TRUE = 4e-7, 2e-4  # read noise and shot noise (images' units)


def _scene(k: int, p: int = 1500, seed: int = 0, gain: float = 1.0):  # type: ignore[no-untyped-def]
    """K observations of P matte pixels (normals near the view axis, varied albedo) under
    lights from a cap, with noise of variance ``A + B × signal``; the exact normals/albedo."""
    rng = np.random.default_rng(seed)
    lights = fibonacci_cap(k, 40.0)
    n = rng.normal(size=(p, 3)) * [0.1, 0.1, 0.0] + [0.0, 0.0, 1.0]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    albedo = gain * rng.uniform(0.2, 0.9, p)
    clean = albedo[None, :] * np.maximum(lights @ n.T, 0.0)  # (K, P)
    noisy = clean + rng.normal(size=clean.shape) * np.sqrt(A_TRUE + B_TRUE * clean)
    return lights, noisy, n, albedo


def _model(k: int, gain: float = 1.0, seed: int = 0):  # type: ignore[no-untyped-def]
    """The object model on the least-squares fit of each pixel (as the robust fit's, its
    residuals have K − 3 degrees of freedom)."""
    lights, obs, _, _ = _scene(k, seed=seed, gain=gain)
    g = np.linalg.lstsq(lights, obs, rcond=None)[0].T  # (P, 3)
    albedo = np.linalg.norm(g, axis=1)
    n = g / albedo[:, None]
    valid = np.ones(len(albedo), dtype=bool)
    return fit_object_model(obs, lights, n, albedo, valid, dark=1e-3, noise_floor=1e-4)


@pytest.mark.parametrize(("k", "seed"), [(6, 0), (12, 1), (12, 2)])
def test_the_fit_finds_synthetic_shot_noise(k: int, seed: int) -> None:
    model = _model(k, seed=seed)
    assert model.noise_var0 is not None
    assert model.noise_slope == pytest.approx(B_TRUE, rel=0.25)
    # the deviation it draws with: ~0 in the dark, √(a + b s) in the light
    sd = np.asarray(model.noise_sd(np.array([0.0, 0.5])))
    assert sd[0] < 0.4 * sd[1]
    assert sd[1] == pytest.approx(np.sqrt(A_TRUE + B_TRUE * 0.5), rel=0.15)


def test_the_residuals_are_standardized_by_their_leverage() -> None:
    """Five lights per pixel leave two degrees of freedom, shared by the lights by leverage,
    and each residual mixes the noise of the pixel's observations: its square over (1 − h) is,
    in expectation, the noise variance at the signal it stands for (shot noise here)."""
    rng = np.random.default_rng(3)
    lights = fibonacci_cap(5, 20.0)
    p = 40000
    n = np.tile([0.0, 0.0, 1.0], (p, 1))
    clean = 0.5 * np.maximum(lights @ n.T, 0.0)  # (K, P): the lights' signals differ
    b = 1e-4
    obs = clean + rng.normal(size=clean.shape) * np.sqrt(b * clean)
    g = np.linalg.lstsq(lights, obs, rcond=None)[0]  # (3, P) least squares per pixel
    resid = obs - lights @ g
    r2, s_eff, good = standardized_residuals2(resid, clean, lights, np.ones_like(obs, bool))
    assert good.all()
    np.testing.assert_allclose(r2.mean(axis=1), b * s_eff[:, 0], rtol=0.04)
    # not the light's own signal: the dimmest light's residual carries the others' noise
    dim = int(np.argmin(clean[:, 0]))
    assert s_eff[dim, 0] > 1.05 * clean[dim, 0]
    assert r2[dim].mean() > 1.05 * b * clean[dim, 0]


def test_the_closed_form_leverages_match_the_hat_matrix_on_a_partial_mask() -> None:
    """The closed form (no (P, K, K) arrays) against the definition, pixel by pixel, where
    each pixel uses its own subset of the lights: H = A (AᵀWA)⁻¹ AᵀW, M = (diag(w) − H)²,
    the signal a residual stands for M·s / ΣM, its square over 1 − h."""
    rng = np.random.default_rng(11)
    k, p = 12, 50
    lights = fibonacci_cap(k, 15.0)
    use = rng.random((k, p)) < 0.7
    use[:3, :5] = False  # a few pixels with fewer lights, down to too few
    use[3:, 5] = False  # pixel 5: 3 lights, no evidence
    resid = rng.normal(size=(k, p))
    sig = rng.random((k, p)) + 0.1
    r2, s_eff, good = standardized_residuals2(resid, sig, lights, use)
    for px in range(p):
        w = use[:, px].astype(float)
        if w.sum() < 4:
            assert not good[:, px].any()
            continue
        hat = lights @ np.linalg.inv(lights.T @ (w[:, None] * lights)) @ (lights.T * w)
        m = (np.diag(w) - hat) ** 2
        one_h = w - np.diag(hat) * w
        ok = use[:, px] & (one_h >= 0.1)
        np.testing.assert_array_equal(good[:, px], ok)
        want_s = (m @ (w * sig[:, px])) / np.maximum(m @ w, 1e-300)
        np.testing.assert_allclose(s_eff[ok, px], want_s[ok], rtol=1e-9)
        np.testing.assert_allclose(r2[ok, px], resid[ok, px] ** 2 / one_h[ok], rtol=1e-9)
    assert not good[:, 5].any() and good.any()


def test_three_lit_lights_give_no_noise_evidence() -> None:
    """A pixel fitted on 3 lights has residual 0 whatever the noise: no evidence, and the model
    keeps its constant (the tilted plane's first decision)."""
    lights = fibonacci_cap(3, 20.0)
    ones = np.ones((3, 50))
    _, _, good = standardized_residuals2(ones, ones, lights, np.ones((3, 50), dtype=bool))
    assert not good.any()
    model = _model(3)
    assert model.noise_var0 is None
    assert model.noise_sd(np.ones((2, 3))) == model.noise


@pytest.mark.parametrize(
    ("signal", "resid2"),
    [
        (np.full(500, 0.3), np.full(500, 1e-5)),  # one signal level: a and b not separable
        (np.linspace(0.1, 0.5, 40), np.full(40, 1e-5)),  # too few observations
        (np.linspace(0.1, 0.5, 800), np.linspace(2e-5, 1e-5, 800)),  # noise falls with signal
        # misfit growing with the signal (a camera of 20 electrons at full scale): not noise
        (np.linspace(0.1, 0.5, 800), 0.05 * np.linspace(0.1, 0.5, 800) * 0.4549),
    ],
)
def test_the_fit_falls_back_to_the_constant(signal: np.ndarray, resid2: np.ndarray) -> None:
    assert fit_noise_model(signal, resid2, 1e-3) is None


def test_the_intercept_keeps_the_floor() -> None:
    s = np.linspace(0.05, 0.8, 2000)
    a, b = fit_noise_model(s, 1e-4 * s * adaptive_bias._CHI2_1_MEDIAN, 0.002) or (0.0, 0.0)
    assert b == pytest.approx(1e-4, rel=1e-6)
    assert a == pytest.approx(0.002**2)


def test_switched_off_the_model_keeps_one_constant(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(adaptive_bias, "SIGNAL_NOISE", False)
    model = _model(12)
    assert model.noise_var0 is None and model.noise_slope == 0.0


def test_each_observation_is_drawn_with_its_own_deviation() -> None:
    """The same unit draws (common random numbers) scaled per observation."""
    lights = fibonacci_cap(5, 20.0)
    unit = light_noise(lights, 2, 30, 1.0, 11)
    sd = np.linspace(0.0, 0.02, 5 * 30).reshape(5, 30)
    np.testing.assert_array_equal(light_noise(lights, 2, 30, sd, 11), unit * sd[None])


def test_a_dark_photograph_adds_little_noise_to_its_reference() -> None:
    """The held-out photograph's noise is its own: a light leaving the object dark scores the
    relighting's own error there, not the bright lights' noise."""
    ref = np.array([[0.0] * 4, [0.5] * 4])
    relit = ref + 0.001
    sd = np.array([[0.0] * 4, [0.01] * 4])
    per_obs = mean_psnr_db(relit, ref, sd)
    const = mean_psnr_db(relit, ref, float(np.sqrt((sd**2).mean())))
    assert per_obs > const + 3.0
    assert mean_psnr_db(relit, ref, np.zeros_like(ref)) == pytest.approx(60.0)


def _plane_shots(k: int):  # type: ignore[no-untyped-def]
    """A matte plane tilted 30° with a gentle relief, shot under ``k`` lights from a cap with
    the simulator's shot noise (variance 1.7·10⁻⁵ × signal)."""
    size = 48
    rows, cols = np.indices((size, size), dtype=np.float64)
    h = -np.tan(np.radians(30.0)) * cols + 2.0 * np.sin(cols / 9.0) * np.cos(rows / 11.0)
    d_row, d_col = np.gradient(h)
    n = np.stack([-d_col, d_row, np.ones_like(h)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    albedo = 0.55 + 0.1 * np.cos(rows / 7.0)
    rng = np.random.default_rng(5)
    lights = fibonacci_cap(k, 25.0)
    shots = []
    for v in lights:
        clean = albedo * np.maximum(n @ v, 0.0)
        shots.append(np.maximum(clean + rng.normal(size=clean.shape) * np.sqrt(1.7e-5 * clean), 0))
    return lights, shots


def test_the_chooser_model_measures_the_cameras_shot_noise() -> None:
    """Through the chooser (the robust fit's residuals, as a session has them): after 12
    images its model's noise is the camera's shot noise within 35 % (plus the noise floor in
    the dark); after 4 (one residual degree of freedom, a narrow signal range) it keeps the
    constant."""
    from rti_rig.app.usecases.adaptive import AdaptiveChooser
    from rti_rig.planner.adaptive import object_model

    lights, shots = _plane_shots(12)
    chooser = AdaptiveChooser(lights, list(range(4)), 12, design_lights=12, objective="relight")
    for i in range(4):
        chooser.observe(i, lights[i], shots[i])
    early = object_model(chooser.state())
    assert early is not None
    for i in range(4, 12):
        chooser.observe(i, lights[i], shots[i])
    model = object_model(chooser.state())
    assert model is not None and model.noise_var0 is not None
    assert model.noise_slope == pytest.approx(1.7e-5, rel=0.35)
    floor = chooser.state().noise_floor  # the intercept's floor: 0.3 % of the bright level
    assert model.noise_var0 == pytest.approx(floor**2, rel=0.5)
    sd = np.asarray(model.noise_sd(np.array([0.05, 0.5])))
    assert sd[1] == pytest.approx(np.sqrt(1.7e-5 * 0.5 + floor**2), rel=0.2)
    assert sd[0] < 0.7 * sd[1]
    assert early.noise_var0 is None


def test_the_error_estimate_keeps_the_constant_and_the_ranking_takes_the_shot_noise() -> None:
    """``--until-error``'s estimate is calibrated with the constant noise (the coin stopped
    early with the signal-dependent one); the designs' scores draw each observation's own."""
    from rti_rig.planner.adaptive_bias import simulate_designs, simulate_error_deg

    model = _model(12)
    assert model.noise_var0 is not None

    def fit(obs, lights):  # type: ignore[no-untyped-def]
        g = np.linalg.lstsq(lights, obs.astype(np.float64), rcond=None)[0].T
        return g / np.linalg.norm(g, axis=1, keepdims=True), np.ones(len(g), dtype=bool)

    lights = fibonacci_cap(8, 40.0)
    est = simulate_error_deg(model, lights, fit)
    assert est == simulate_designs(model, [lights], fit, signal_noise=False)[0]
    assert est != simulate_designs(model, [lights], fit)[0]


@pytest.mark.parametrize("ks", [0.02, 0.05, 0.3])
def test_the_gloss_the_model_renders_is_not_taken_for_noise(ks: float) -> None:
    """On a glossy surface the noise is fitted against what the model renders — the
    Lambertian part and the fitted lobe — not the Lambertian part alone, which counted the
    gloss twice (as lobe and as noise growing with the signal). Constant noise: the constant
    is kept; shot noise: its slope found whatever the gloss."""
    from rti_rig.planner.adaptive_bias import _half_cos, _lobe, fit_object_model

    rng = np.random.default_rng(1)
    p = 2000
    lights = fibonacci_cap(18, 15.0)
    n = rng.normal(size=(p, 3)) * [0.3, 0.3, 1.0]
    n[:, 2] = np.abs(n[:, 2]) + 0.6
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    albedo = rng.uniform(0.3, 0.6, p)
    cos = lights @ n.T
    signal = albedo[None] * np.maximum(cos, 0) + ks * _lobe(_half_cos(n, lights).T, 16.0) * (
        cos > 0
    )

    def model(var):  # type: ignore[no-untyped-def]
        obs = np.maximum(signal + rng.normal(size=signal.shape) * np.sqrt(var), 0.0)
        return fit_object_model(obs, lights, n, albedo, np.ones(p, bool), 0.01, 0.003)

    flat = model(np.full(signal.shape, 0.004**2))
    assert flat.noise_slope == 0.0  # constant noise: no slope (the lobe's residual was one)
    shot = model(1e-6 + 1.7e-4 * signal)
    assert 1.7e-4 / 1.6 < shot.noise_slope < 1.7e-4 * 1.6
