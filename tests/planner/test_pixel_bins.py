"""The binned pixel sample the `optimal` search sweeps on: what it merges, what it keeps, and
that plans found on it are as good, on the full sample's objective, as plans found on that."""

from __future__ import annotations

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from rti_rig.core.geometry import direction_from_az_el, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.make_plan import _candidates_and_starts, _held_out_lights, plan_with_report
from rti_rig.planner.objectives import (
    Candidates,
    NormalsObjective,
    RelightObjective,
    SurfaceSample,
)
from rti_rig.planner.optimal import exchange_search
from rti_rig.planner.pixel_bins import _cell_means, _mean_rows, bin_pixels, binned_objective
from rti_rig.planner.surface_estimate import estimate_surface, flat_surface, sample_surface
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

ARM = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)
DOME = DomeGeometry(fibonacci_cap(120, 5.0), tuple(f"led_{i:03d}" for i in range(120)))


def preview_problem(geometry, n: int, seed: int = 0, light=(30.0, 50.0)):
    scene = relief_scene(96, 128, seed=seed)
    preview = lambert_radiance(scene, direction_from_az_el(*light)).astype(np.float32)
    surface = estimate_surface(preview, light)
    cands, starts = _candidates_and_starts(geometry, n, 0.0, 90.0)
    sample = sample_surface(surface, cands, _held_out_lights(cands, (0.0, 90.0), False))
    return cands, starts, sample


def tiny_sample() -> tuple[SurfaceSample, Candidates]:
    """Five pixels: 0 and 2 a hair apart (one cell), 3 like 0 but shadowed from light 1."""
    cands = Candidates(fibonacci_cap(4, 20.0, 80.0), None, None)
    n = direction_from_az_el(
        np.array([10.0, 200.0, 10.2, 10.0, 90.0]), np.array([80.0, 60.0, 80.1, 80.0, 70.0])
    )
    lit = np.ones((5, 4))
    lit[3, 1] = 0.0
    held = fibonacci_cap(6, 5.0, 90.0)
    return SurfaceSample(n, np.array([1.0, 2.0, 3.0, 1.0, 1.0]), lit, held, np.ones((5, 6))), cands


def test_bins_merge_near_normals_with_the_same_shadows_only() -> None:
    sample, _ = tiny_sample()
    binned = bin_pixels(sample, 2.0, bias_pixels=3)
    # 0 and 2 merge (0.2° apart, same shadows); 3 has 0's normal but another shadow row
    assert len(binned.normals) == 4
    np.testing.assert_allclose(binned.weights, np.array([4.0, 2.0, 1.0, 1.0]) / 8.0)
    mean = (sample.normals[0] * 1.0 + sample.normals[2] * 3.0) / 4.0
    np.testing.assert_allclose(binned.normals[0], mean / np.linalg.norm(mean))
    np.testing.assert_array_equal(binned.lit_candidates[2], sample.lit_candidates[3])
    # the first 3 pixels (the bias sub-sample) fall in the first 2 rows, weighted 1+3 and 2
    assert binned.bias_weights is not None
    np.testing.assert_allclose(binned.bias_weights, np.array([4.0, 2.0]) / 8.0)


def test_zero_bin_merges_only_identical_pixels_and_keeps_the_costs() -> None:
    """bin 0 on a level surface: its 1792 rows become the 7 the exact merge finds, same costs."""
    cands = Candidates(fibonacci_cap(40, 5.0, 88.0), None, None)
    sample = sample_surface(flat_surface(), cands, fibonacci_cap(30, 5.0, 90.0))
    exact = NormalsObjective(sample, cands)
    binned = NormalsObjective(bin_pixels(sample, 0.0), cands)
    assert len(binned.n) == len(exact.n) == 7
    for chosen in (np.arange(0, 40, 5), np.array([1, 4, 9, 16, 25, 36])):
        assert binned.cost(chosen) == pytest.approx(exact.cost(chosen), rel=1e-12)


def test_binned_costs_are_close_to_the_full_samples() -> None:
    """From a preview the sample's 1792 rows bin to well under half, and any layout's cost
    moves by well under 1 % (second order in the cell size)."""
    cands, starts, sample = preview_problem(ARM, 24)
    exact = NormalsObjective(sample, cands)
    binned = binned_objective(exact)
    assert isinstance(binned, NormalsObjective) and binned is not exact
    assert len(binned.n) < 0.6 * len(exact.n)
    rng = np.random.default_rng(0)
    layouts = [s for _, s in starts] + [rng.choice(len(cands), 24, replace=False) for _ in range(5)]
    for chosen in layouts:
        assert binned.cost(chosen) == pytest.approx(exact.cost(chosen), rel=5e-3)
    # finer cells, closer costs: the error is the cells' (no other approximation)
    fine = NormalsObjective(bin_pixels(sample, 0.25), cands)
    gaps = [abs(o.cost(layouts[0]) / exact.cost(layouts[0]) - 1) for o in (fine, binned)]
    assert gaps[0] < gaps[1]


def test_no_stand_in_where_binning_saves_nothing() -> None:
    """No preview: the objective's 7 rows already; relight: its cost does not see pixels."""
    cands = Candidates(fibonacci_cap(40, 5.0, 88.0), None, None)
    sample = sample_surface(flat_surface(), cands, fibonacci_cap(30, 5.0, 90.0))
    normals = NormalsObjective(sample, cands)
    assert binned_objective(normals) is normals
    relight = RelightObjective(sample, cands, "ptm")
    assert binned_objective(relight) is relight
    assert binned_objective(normals, 0.0) is normals


@pytest.mark.parametrize(
    ("geometry", "n", "seed"),
    [(ARM, 24, 0), (ARM, 50, 1), (ARM, 100, 2), (DOME, 30, 0), (DOME, 60, 1)],
)
def test_plans_searched_on_bins_are_within_one_percent_of_the_full_search(
    geometry, n, seed
) -> None:
    """The quality guard of the speed-up: on the full sample's objective, the plan the binned
    search finds costs at most 1 % more than the plan the full search finds, is cheaper than its
    start, and its reported cost is the full objective's."""
    light = (30.0 + 40.0 * seed, 50.0)
    cands, starts, sample = preview_problem(geometry, n, seed, light)
    exact = NormalsObjective(sample, cands)
    with threadpool_limits(limits=1):
        full = exchange_search(exact, starts)
        fast = exchange_search(exact, starts, search=binned_objective(exact))
    assert fast.cost == pytest.approx(exact.cost(fast.chosen), rel=1e-12)
    assert fast.cost <= full.cost * 1.01
    assert fast.cost < fast.start_cost and fast.swaps > 0
    assert len(set(fast.chosen.tolist())) == n


class Misleading:
    """A stand-in that ranks layouts backwards (minus the true cost)."""

    def __init__(self, objective: NormalsObjective) -> None:
        self.objective = objective
        self.candidate_count = objective.candidate_count

    def cost(self, chosen: np.ndarray) -> float:
        return -self.objective.cost(chosen)

    def swap_costs(self, chosen, position, exact=False, among=None) -> np.ndarray:
        return -self.objective.swap_costs(chosen, position, exact=exact, among=among)


def test_a_stand_in_that_misleads_cannot_make_the_plan_worse_than_its_start() -> None:
    cands, starts, sample = preview_problem(DOME, 12)
    exact = NormalsObjective(sample, cands)
    misleading = Misleading(exact)
    res = exchange_search(exact, starts, max_passes=1, search=misleading)  # type: ignore[arg-type]
    best = min(starts, key=lambda s: exact.cost(s[1]))
    np.testing.assert_array_equal(res.chosen, best[1])
    assert res.cost == res.start_cost == exact.cost(best[1]) and res.swaps == 0


def test_the_plan_report_says_the_search_was_binned() -> None:
    scene = relief_scene(96, 128, seed=0)
    preview = lambert_radiance(scene, direction_from_az_el(30.0, 50.0)).astype(np.float32)
    _, report = plan_with_report(preview, ARM, 24, "optimal", "normals", (30.0, 50.0))
    assert report.search_pixels is not None
    every, binned = report.search_pixels
    assert every == 1792 and binned < every
    assert any(f"searched on {binned} binned pixel rows of {every}" in ln for ln in report.lines())
    _, flat = plan_with_report(None, ARM, 24, "optimal", "normals")
    assert flat.search_pixels is None


def test_pixel_bin_zero_turns_the_binning_off(monkeypatch) -> None:
    """`PIXEL_BIN_DEG = 0`: the search sweeps every pixel row, and the plan is the one of the
    search on the objective itself."""
    from rti_rig.planner import pixel_bins

    scene = relief_scene(96, 128, seed=0)
    preview = lambert_radiance(scene, direction_from_az_el(30.0, 50.0)).astype(np.float32)
    monkeypatch.setattr(pixel_bins, "PIXEL_BIN_DEG", 0.0)
    _, report = plan_with_report(preview, ARM, 24, "optimal", "normals", (30.0, 50.0))
    assert report.search_pixels is None
    cands, starts, sample = preview_problem(ARM, 24)
    exact = NormalsObjective(sample, cands)
    with threadpool_limits(limits=1):
        want = exchange_search(exact, starts)
    assert report.expected["optimal"] == pytest.approx(want.cost, rel=1e-12)


def test_grazing_lights_do_not_split_cells_and_leave_their_lit_fraction() -> None:
    """Pixels 0 and 3 share a cell; 3 is shadowed from light 1. When light 1 is grazing its
    shadow no longer splits them: the row holds their weighted lit fraction for it. The held-out
    lights' shadows split cells unless told not to (the normals objective never reads them)."""
    sample, _ = tiny_sample()
    grazing = np.array([False, True, False, False])
    binned = bin_pixels(sample, 2.0, bias_pixels=3, grazing=grazing)
    assert len(binned.normals) == 3  # {0, 2, 3}, {1}, {4}
    np.testing.assert_allclose(binned.weights, np.array([5.0, 2.0, 1.0]) / 8.0)
    np.testing.assert_allclose(binned.lit_candidates[0], [1.0, 4.0 / 5.0, 1.0, 1.0])
    np.testing.assert_array_equal(binned.lit_candidates[1:], 1.0)
    # a non-grazing light's shadow still splits
    assert len(bin_pixels(sample, 2.0, grazing=np.array([True, False, True, True])).normals) == 4
    held = sample.lit_held_out.copy()
    held[2, 0] = 0.0  # pixel 2 (in 0's cell) shadowed from a held-out light
    split = SurfaceSample(sample.normals, sample.weights, sample.lit_candidates,
                          sample.held_out, held)  # fmt: skip
    assert len(bin_pixels(split, 2.0).normals) == 5
    merged = bin_pixels(split, 2.0, held_out_shadows=False)
    assert len(merged.normals) == 4
    np.testing.assert_allclose(merged.lit_held_out[0, 0], 1.0 / 4.0)


def shipped_arm() -> ArmGeometry:
    from pathlib import Path

    from rti_rig.app.config import load_rig_config, rig_geometry

    repo = Path(__file__).resolve().parents[2]
    geometry = rig_geometry(load_rig_config(repo / "rig_configs" / "simulated_arm.toml"))
    assert isinstance(geometry, ArmGeometry)
    return geometry


@pytest.mark.parametrize(("n", "seed"), [(100, 0), (75, 2)])
def test_on_the_shipped_arm_grazing_lights_no_longer_keep_every_pixel_apart(n, seed) -> None:
    """`simulated_arm.toml` reaches down to 0°, so nearly every pixel is shadowed from some
    candidate of its own: with the lights under GRAZING_DEG left out of the cells' key the
    1792 rows bin to well under 1200 (1480 and 1614 when every shadow split), and the binned
    search's plan is within 1 % of the full search's on every pixel."""
    from rti_rig.planner import pixel_bins

    arm = shipped_arm()
    light = (30.0 + 40.0 * seed, 50.0)
    cands, starts, sample = preview_problem(arm, n, seed, light)
    assert np.degrees(np.arcsin(cands.directions[:, 2].min())) < pixel_bins.GRAZING_DEG
    exact = NormalsObjective(sample, cands)
    binned = binned_objective(exact)
    strict = binned_objective(exact, grazing_deg=0.0)
    assert len(binned.n) < 1200 < len(strict.n)
    with threadpool_limits(limits=1):
        full = exchange_search(exact, starts)
        fast = exchange_search(exact, starts, search=binned)
    assert fast.cost <= full.cost * 1.01
    assert fast.cost < fast.start_cost and fast.swaps > 0


def test_cell_means_are_the_dense_products_means() -> None:
    """The held-out rows of a binned sample are summed cell by cell (no dense cells × pixels
    matrix): the same weighted means as the dense product, to rounding."""
    rng = np.random.default_rng(3)
    for cells, pixels, cols in ((1, 5, 3), (40, 300, 17), (861, 1792, 160)):
        group = np.concatenate([np.arange(cells), rng.integers(0, cells, pixels - cells)])
        group = rng.permutation(group)
        wts = rng.random(pixels)
        weight = np.bincount(group, weights=wts, minlength=cells)
        values = (rng.random((pixels, cols)) > 0.3).astype(np.float64)
        want = _mean_rows(values, group, wts, weight)
        got = _cell_means(values, group, wts, weight)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
