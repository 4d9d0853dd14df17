"""Model choice: the lowest order that predicts held-out lights within tolerance of the best."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.geometry import direction_from_az_el
from rti_rig.reconstruct import ReconstructionError, design_matrix, select_model
from rti_rig.reconstruct.synthetic import fibonacci_lights, render, sphere_normals


def _noisy(model: str, n_lights: int, seed: int = 0, noise: float = 0.003):
    rng = np.random.default_rng(seed)
    lights = fibonacci_lights(n_lights)
    p = design_matrix(model, lights).shape[1]
    coef = rng.normal(0, 0.3, (p, 20, 20))
    images = np.tensordot(design_matrix(model, lights), coef, axes=(1, 0))
    images += 2.0 - images.min()  # keep positive: the relighting is clamped at zero
    images += rng.normal(0, noise, images.shape)
    return images.astype(np.float32), lights


@pytest.mark.parametrize("model", ["ptm", "hsh2", "hsh3"])
def test_scene_generated_by_a_model_selects_it(model: str) -> None:
    images, lights = _noisy(model, 60)
    choice = select_model(images, lights)
    assert choice.model == model, choice.to_markdown()
    rows = {e.model: e for e in choice.evidence}
    assert rows[model].within_tolerance
    assert rows["lambert"].rmse > 3 * rows[model].rmse


def test_unshadowed_lambertian_scene_needs_only_lambert() -> None:
    rng = np.random.default_rng(4)
    tilt = np.radians(rng.uniform(0, 20, (16, 16)))
    az = rng.uniform(0, 2 * np.pi, (16, 16))
    normals = np.stack([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), np.cos(tilt)], -1)
    lights = direction_from_az_el(np.arange(40) * 47.0, 72.0 + 15.0 * (np.arange(40) % 2))
    images = render(normals, 0.5, lights) + rng.normal(0, 0.002, (40, 16, 16)).astype(np.float32)
    choice = select_model(images, lights, tolerance=0.05)
    assert choice.model == "lambert", choice.to_markdown()


def test_shadowed_sphere_needs_more_than_lambert() -> None:
    normals, _ = sphere_normals(32, 32)
    lights = fibonacci_lights(50)
    choice = select_model(render(normals, 0.6, lights), lights)
    assert choice.model != "lambert"
    rows = {e.model: e for e in choice.evidence}
    assert rows["lambert"].rmse > rows[choice.model].rmse * 1.05


def test_too_few_lights_skip_high_orders_with_reason() -> None:
    images, lights = _noisy("ptm", 10)
    choice = select_model(images, lights, holdout=5)
    rows = {e.model: e for e in choice.evidence}
    assert rows["hsh2"].rmse is None and "needs 9 fitting lights" in rows["hsh2"].note
    assert rows["hsh3"].rmse is None
    assert choice.model == "ptm"
    assert "| hsh3 | 16 | — |" in choice.to_markdown()


def test_explicit_holdout_and_refit() -> None:
    images, lights = _noisy("hsh2", 30)
    choice = select_model(images, lights, holdout=[0, 7, 14, 21, 28])
    assert "held out" in choice.holdout
    assert choice.model == "hsh2"
    model = choice.fit(images, lights)
    assert model.n_coefficients == 9


def test_large_tolerance_takes_the_lowest_order() -> None:
    images, lights = _noisy("hsh3", 40)
    assert select_model(images, lights, tolerance=1e4).model == "lambert"


def test_no_fittable_candidate_is_an_error() -> None:
    images, lights = _noisy("lambert", 4)
    with pytest.raises(ReconstructionError, match="no candidate"):
        select_model(images, lights, holdout=2, candidates=["ptm", "hsh2"])
    with pytest.raises(ReconstructionError, match="held-out light indices"):
        select_model(images, lights, holdout=[9])
