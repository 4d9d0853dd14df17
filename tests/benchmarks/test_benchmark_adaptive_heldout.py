"""``benchmarks.adaptive_heldout``: object-model variants judged on held-out captured images,
and ``benchmarks.adaptive --heldout-score`` scoring the chooser's designs by them."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import adaptive, adaptive_heldout
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner.adaptive import SurfaceState, object_model


def _matte_state(k: int = 8, side: int = 24, noise: float = 0.003) -> SurfaceState:
    """A matte, gently rippled Lambertian surface under ``k`` lights, as the chooser sees it."""
    rows, cols = np.mgrid[0:side, 0:side]
    rows, cols = rows.ravel(), cols.ravel()
    n = np.c_[0.15 * np.sin(cols / 4.0), 0.1 * np.cos(rows / 5.0), np.ones(rows.size)]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    albedo = np.full(rows.size, 0.6)
    lights = fibonacci_cap(k, 25.0)
    rng = np.random.default_rng(3)
    clean = (albedo[:, None] * np.clip(n @ lights.T, 0.0, None)).T
    obs = (clean + rng.normal(0.0, noise, clean.shape)).astype(np.float32)
    return SurfaceState(
        normals=n,
        albedo=albedo,
        noise=np.full(rows.size, noise),
        lit=(n @ lights.T) > 0,
        lights=lights,
        obs=obs,
        valid=np.ones(rows.size, dtype=bool),
        dark=0.01,
        noise_floor=0.001,
        rows=rows,
        cols=cols,
        height=np.zeros((side, side)),
    )


def test_held_out_images_favour_the_matte_variant_of_a_matte_object() -> None:
    state = _matte_state()
    model = object_model(state)
    assert model is not None
    vs = adaptive_heldout.variants(model)
    assert set(vs) == set(adaptive_heldout.VARIANTS)
    losses = adaptive_heldout.heldout_losses(state, model, vs)
    assert all(v.size == len(state.lights) for v in losses.values())
    assert losses["matte"].mean() < losses["glossy"].mean()


def test_heldout_score_replaces_the_chooser_s_design_score(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--heldout-score mean``: the chooser's designs are scored by the mean over the variants
    of the simulated robust fit; without the option the planner is left as it ships."""
    import rti_rig.planner.adaptive as planner
    from rti_rig.app.usecases.adaptive import robust_fit
    from rti_rig.planner.adaptive_bias import simulate_designs

    monkeypatch.setattr(planner, "object_model", planner.object_model)
    monkeypatch.setattr(planner, "simulate_designs", planner.simulate_designs)
    shipped = planner.simulate_designs
    adaptive.configure_planner(adaptive.build_parser().parse_args([]))
    assert planner.simulate_designs is shipped
    adaptive.configure_planner(adaptive.build_parser().parse_args(["--heldout-score", "mean"]))
    assert planner.simulate_designs is not shipped
    state = _matte_state()
    model = planner.object_model(state)
    designs = [fibonacci_cap(9, f) for f in (10.0, 30.0)]
    got = planner.simulate_designs(model, designs, robust_fit)
    want = np.mean(
        [
            simulate_designs(m, designs, robust_fit)
            for m in adaptive_heldout.variants(model).values()
        ],
        axis=0,
    )
    assert np.allclose(got, want)


def test_the_truly_predicting_variant_of_a_matte_object_is_not_the_glossy_one() -> None:
    """``truth-pred``: the variant whose renderings best predict the true images of the lights
    not shot (here noise-free Lambertian ones) — never the one given a lobe the object lacks."""
    state = _matte_state()
    model = object_model(state)
    assert model is not None
    dirs = fibonacci_cap(40, 10.0)
    n, albedo = state.normals, state.albedo
    truth = (albedo[:, None] * np.clip(n @ dirs.T, 0.0, None)).T  # (L, P), the sample's order
    cols = adaptive_heldout.sample_columns(model, truth.shape[1])
    assert np.array_equal(cols, np.arange(truth.shape[1]))
    vs = adaptive_heldout.variants(model)
    assert adaptive_heldout.truly_predicting(dirs, model, vs, truth, [0, 1]) != "glossy"


def test_heldout_score_variant_scores_on_that_variant_alone(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--heldout-score variant-smooth``: the designs scored on the smooth variant only; an
    unknown name is refused."""
    import rti_rig.planner.adaptive as planner
    from rti_rig.app.usecases.adaptive import robust_fit
    from rti_rig.planner.adaptive_bias import simulate_designs

    monkeypatch.setattr(planner, "object_model", planner.object_model)
    monkeypatch.setattr(planner, "simulate_designs", planner.simulate_designs)
    adaptive_heldout.install("variant-smooth")
    model = planner.object_model(_matte_state())
    designs = [fibonacci_cap(9, f) for f in (10.0, 30.0)]
    got = planner.simulate_designs(model, designs, robust_fit)
    want = simulate_designs(adaptive_heldout.variants(model)["smooth"], designs, robust_fit)
    assert np.allclose(got, want)
    with pytest.raises(SystemExit, match="one of"):
        adaptive_heldout.install("variant-shiny")


def test_bar_regret_divides_each_variant_by_its_own_best_layout() -> None:
    """Design 0 is at the bar for both variants; design 1 is twice variant a's bar. Raw
    ``minimax`` is ruled by the hard variant b (errors 10 against 9) and prefers design 1; the
    bar regret prefers design 0 (worst ratio 1 against 2)."""
    sims = {"a": [2.0, 4.0], "b": [10.0, 9.0]}
    bars = {"a": [3.0, 2.0, 5.0], "b": [12.0, 10.0]}
    assert adaptive_heldout.bar_regret(sims, bars) == pytest.approx([1.0, 2.0])
    raw = np.max([sims["a"], sims["b"]], axis=0)
    assert int(np.argmin(raw)) == 1


def test_full_homogeneous_layouts_are_the_bar_s_layouts() -> None:
    """One layout of N per shipped floor, the candidates ``select_uniform_leds`` takes (the
    bar's layouts), whatever lights a session has shot."""
    from rti_rig.core.rig_geometry import DomeGeometry
    from rti_rig.planner.uniform import select_uniform_leds

    dirs = fibonacci_cap(60, 0.0)
    dome = DomeGeometry(dirs, tuple(f"c{i:02d}" for i in range(len(dirs))))
    homs = adaptive_heldout.full_homogeneous(dirs, 9)
    assert len(homs) == len(adaptive_heldout.FLOORS)
    for f, h in zip(adaptive_heldout.FLOORS, homs, strict=True):
        want = dirs[select_uniform_leds(dome, 9, f)]
        assert sorted(map(tuple, np.round(h, 9))) == sorted(map(tuple, np.round(want, 9)))
