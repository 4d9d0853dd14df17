"""Objectives against closed forms, batched swaps against direct costs, the paper's k-means."""

from __future__ import annotations

import numpy as np
import pytest

from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import angle_between_deg, direction_from_az_el, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.kmeans_method import cluster_normals, kmeans_targets, plan_kmeans
from rti_rig.planner.objectives import (
    MAX_ERR2,
    NOISE_REL,
    Candidates,
    NormalsObjective,
    RelightObjective,
    SurfaceSample,
    candidates_for,
    models_for,
    snap_unique,
)
from rti_rig.planner.optimal import exchange_search

SLANT_OPT = np.degrees(np.arccos(1 / np.sqrt(3)))  # 54.74°, Drbohlav & Chantler


def make_sample(normals: np.ndarray, cands: Candidates, specular: float = 0.0) -> SurfaceSample:
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    held = fibonacci_cap(60, 5.0, 90.0)
    return SurfaceSample(
        n, np.ones(len(n)), np.ones((len(n), len(cands))), held, np.ones((len(n), 60)), specular
    )


def ring(n: int, elevation_deg: float) -> np.ndarray:
    return direction_from_az_el(np.arange(n) * 360.0 / n, np.full(n, elevation_deg))


@pytest.mark.parametrize("n", [3, 4, 6, 8, 16])
def test_normals_objective_matches_the_cramer_rao_bound(n: int) -> None:
    """Flat normal, ring at 54.74° slant, no bias term: RMS error = sqrt(6/N)·σ/ρ rad."""
    cands = Candidates(ring(n, 90 - SLANT_OPT), None, None)
    sample = make_sample([[0, 0, 1.0]], cands)
    obj = NormalsObjective(sample, cands, bias_rel=0.0, gain_rel=0.0)
    expected = np.degrees(np.sqrt(6.0 / n) * NOISE_REL)
    assert obj.cost(np.arange(n)) == pytest.approx(expected, rel=1e-6)
    # signal-proportional noise g adds (g·n·l)² to every observation's variance: on the ring
    # n·l = cos 54.74° for all lights, so the bound grows by sqrt(1 + (g n·l / σ)²)
    shading = np.cos(np.radians(SLANT_OPT))
    with_gain = NormalsObjective(sample, cands, bias_rel=0.0, gain_rel=0.05)
    grown = expected * np.sqrt(1.0 + (0.05 * shading / NOISE_REL) ** 2)
    assert with_gain.cost(np.arange(n)) == pytest.approx(grown, rel=1e-6)


def test_signal_proportional_noise_penalises_head_on_light() -> None:
    """With noise that grows with n·l, a light striking the surface head-on is worth less: a
    high ring loses against a low one by the factor the variances predict."""

    def cost(elevation: float, gain: float) -> float:
        cands = Candidates(ring(8, elevation), None, None)
        obj = NormalsObjective(make_sample([[0, 0, 1.0]], cands), cands, 0.0, gain)
        return obj.cost(np.arange(8))

    def factor(elevation: float) -> float:  # growth of the noise std at n·l = sin(elevation)
        return float(np.sqrt(1.0 + (0.05 * np.sin(np.radians(elevation)) / NOISE_REL) ** 2))

    for el in (20.0, 60.0):
        assert cost(el, 0.05) == pytest.approx(cost(el, 0.0) * factor(el), rel=1e-6)
    assert cost(60.0, 0.05) / cost(20.0, 0.05) > 1.5 * cost(60.0, 0.0) / cost(20.0, 0.0)


def test_shadowed_normal_is_unobservable() -> None:
    """A steep normal facing away from one of three high lights sees only two: capped at 90°."""
    cands = Candidates(ring(3, 80.0), None, None)
    tilted = direction_from_az_el(180.0, 5.0)
    obj = NormalsObjective(make_sample([tilted], cands), cands, bias_rel=0.0)
    assert obj.cost(np.arange(3)) == pytest.approx(np.degrees(np.sqrt(MAX_ERR2)))
    facing = NormalsObjective(make_sample([[0, 0, 1.0]], cands), cands, bias_rel=0.0, gain_rel=0)
    assert facing.cost(np.arange(3)) < 10.0


def test_bias_term_prefers_layouts_that_agree_with_all_lights() -> None:
    cands = Candidates(fibonacci_cap(40, 5.0, 88.0), None, None)
    normals = fibonacci_cap(30, 60.0, 90.0)
    with_bias = NormalsObjective(make_sample(normals, cands), cands, bias_rel=0.05)
    without = NormalsObjective(make_sample(normals, cands), cands, bias_rel=0.0)
    everything = np.arange(40)
    # with every light the fit *is* the reference: no bias left
    assert with_bias.cost(everything) == pytest.approx(without.cost(everything), rel=1e-9)
    few = np.array([0, 10, 20, 30, 35, 39])
    assert with_bias.cost(few) > without.cost(few)


@pytest.mark.parametrize("objective", ["normals", "relight"])
def test_batched_swaps_equal_direct_costs(objective: str) -> None:
    dome = DomeGeometry(fibonacci_cap(30, 5.0, 88.0), tuple(str(i) for i in range(30)))
    cands = candidates_for(dome)
    rng = np.random.default_rng(0)
    normals = fibonacci_cap(25, 45.0, 90.0)
    sample = make_sample(normals, cands, specular=0.3)
    obj = (
        NormalsObjective(sample, cands)
        if objective == "normals"
        else RelightObjective(sample, cands, "ptm")
    )
    chosen = rng.choice(30, 9, replace=False)
    batch = obj.swap_costs(chosen, 4)
    for k in (0, 7, 29):
        trial = chosen.copy()
        trial[4] = k
        # the normals scan runs in single precision (the hot loop); the relight one in double
        assert batch[k] == pytest.approx(
            obj.cost(trial), rel=1e-5 if objective == "normals" else 1e-9
        )


def test_relight_cost_equals_a_per_pixel_held_out_evaluation() -> None:
    """The pixel-summed Gram form equals fitting each pixel and scoring it on held-out lights."""
    from rti_rig.core.rti_bases import design_matrix
    from rti_rig.planner.objectives import reflectance

    rng = np.random.default_rng(3)
    cands = candidates_for(DomeGeometry(fibonacci_cap(40, 5.0, 88.0), tuple(map(str, range(40)))))
    normals = fibonacci_cap(30, 30.0, 90.0)
    held = fibonacci_cap(50, 5.0, 90.0)
    sample = SurfaceSample(
        normals,
        rng.uniform(0.5, 2.0, 30),
        (rng.random((30, 40)) > 0.2).astype(float),  # some cast shadows
        held,
        (rng.random((30, 50)) > 0.2).astype(float),
        0.3,
    )
    obj = RelightObjective(sample, cands, "ptm")
    chosen = rng.choice(40, 10, replace=False)
    a_s = design_matrix("ptm", cands.directions[chosen])
    a_t = design_matrix("ptm", held)
    f_s = reflectance(sample, cands.directions, sample.lit_candidates)[:, chosen]
    f_t = reflectance(sample, held, sample.lit_held_out)
    inv = np.linalg.inv(a_s.T @ a_s + 1e-8 * np.eye(6))
    coef = f_s @ (a_s @ inv)  # (P, p): per-pixel least squares
    per_pixel = np.mean((coef @ a_t.T - f_t) ** 2, axis=1)
    w = sample.weights / sample.weights.sum()
    var = NOISE_REL**2 * np.trace(a_t.T @ a_t / 50 @ inv)
    dev_s, dev_t = design_matrix("hsh3", cands.directions[chosen]), design_matrix("hsh3", held)
    miss = a_t @ (inv @ a_s.T @ dev_s) - dev_t
    unmodelled = obj.tau2 * np.mean(np.sum(miss * miss, axis=1))
    assert obj.cost(chosen) == pytest.approx(per_pixel @ w + var + unmodelled, rel=1e-9)


def test_relight_variance_anchor() -> None:
    """No bias (reflectance in the basis span is impossible to get exactly, so use p/N bound):
    with well spread lights the variance part is close to p σ² / N (algorithms notes §3)."""
    cands = Candidates(fibonacci_cap(36, 5.0, 90.0), None, None)
    sample = SurfaceSample(
        np.array([[0.0, 0.0, 1.0]]),
        np.ones(1),
        np.zeros((1, 36)),
        fibonacci_cap(2000, 5.0, 90.0),
        np.zeros((1, 2000)),
    )  # fully shadowed pixel: reflectance 0 everywhere, so the cost is variance only
    obj = RelightObjective(sample, cands, "ptm", bias_rel=0.0)
    var = obj.cost(np.arange(36))
    assert var == pytest.approx(6 * NOISE_REL**2 / 36, rel=0.5)


def test_unmodelled_reflectance_term_favours_spread_lights() -> None:
    cands = Candidates(fibonacci_cap(60, 5.0, 90.0), None, None)
    sample = make_sample(fibonacci_cap(20, 50.0, 90.0), cands)
    with_term = RelightObjective(sample, cands, "ptm")
    without = RelightObjective(sample, cands, "ptm", bias_rel=0.0)
    spread = np.linspace(0, 59, 12).round().astype(int)
    clumped = np.argsort(-cands.directions[:, 2])[:12]  # the 12 highest lights
    extra_spread = with_term.cost(spread) - without.cost(spread)
    extra_clumped = with_term.cost(clumped) - without.cost(clumped)
    assert 0 < extra_spread < extra_clumped


def test_models_for_light_counts() -> None:
    assert models_for(1) == ["lambert"]
    assert models_for(6) == ["hsh1"]
    assert models_for(9) == ["hsh1", "ptm"]
    assert models_for(30)[-1] == "hsh3"


def test_exchange_never_worse_than_any_start_and_finds_the_ring() -> None:
    """Flat normals, no bias: the optimum tilts lights towards grazing (notes §3, 4/(N cos² e))."""
    cands = Candidates(fibonacci_cap(80, 5.0, 89.0), None, None)
    obj = NormalsObjective(make_sample([[0, 0, 1.0]], cands), cands, bias_rel=0.0)
    start = np.argsort(-cands.directions[:, 2])[:6]  # the six highest lights: a poor start
    res = exchange_search(obj, [("top", start)])
    assert res.cost <= res.start_cost
    assert res.cost < 0.5 * res.start_cost
    el = np.degrees(np.arcsin(cands.directions[res.chosen, 2]))
    assert np.median(el) < 20.0


def test_exchange_accepts_a_swap_only_on_its_exact_cost() -> None:
    """A scan that promises a gain the exact cost does not confirm must change nothing."""

    class OptimisticScan:
        def cost(self, chosen: np.ndarray) -> float:
            return float(np.sum(chosen))  # lower indices are better

        def swap_costs(self, chosen: np.ndarray, position: int, exact: bool = False) -> np.ndarray:
            out = np.full(10, np.inf)
            out[9] = -1.0  # claims that index 9 (the worst) is a great replacement
            return out

    res = exchange_search(OptimisticScan(), [("start", np.array([0, 1, 2]))])  # type: ignore[arg-type]
    assert res.chosen.tolist() == [0, 1, 2]
    assert res.swaps == 0
    assert res.cost == 3.0


def test_a_rejected_fast_proposal_is_followed_by_an_exact_scan() -> None:
    """The fast scan proposes a bad swap; the exact re-scan finds the real improvement."""

    class FastScanWrong:
        def cost(self, chosen: np.ndarray) -> float:
            return float(np.sum(chosen))

        def swap_costs(self, chosen: np.ndarray, position: int, exact: bool = False) -> np.ndarray:
            if not exact:
                out = np.full(10, np.inf)
                out[9] = -1.0
                return out
            return np.array([float(np.sum(chosen) - chosen[position] + k) for k in range(10)])

    res = exchange_search(FastScanWrong(), [("start", np.array([4, 5, 6]))])  # type: ignore[arg-type]
    assert sorted(res.chosen.tolist()) == [0, 1, 2]
    assert res.cost == 3.0


def test_variance_matches_the_trace_formula_on_tilted_normals() -> None:
    """Both precisions of the closed form equal σ² tr(P M⁻¹ P) computed with numpy."""
    cands = Candidates(fibonacci_cap(40, 5.0, 88.0), None, None)
    normals = np.array([direction_from_az_el(a, e) for a, e in [(20, 50), (200, 35), (300, 70)]])
    obj = NormalsObjective(make_sample(normals, cands), cands, bias_rel=0.0)
    chosen = np.array([0, 5, 11, 17, 23, 31, 38])
    m = obj.outer[:, chosen].sum(axis=1)[:, None]  # (6, 1, P)
    want = []
    for p, n in enumerate(normals):
        e = m[:, 0, p]
        mm = np.array([[e[0], e[1], e[2]], [e[1], e[3], e[4]], [e[2], e[4], e[5]]])
        proj = np.eye(3) - np.outer(n, n)
        want.append(NOISE_REL**2 * np.trace(proj @ np.linalg.inv(mm) @ proj))
    assert obj._variance(m)[0] == pytest.approx(want, rel=1e-8)
    assert obj._variance(m.astype(np.float32))[0] == pytest.approx(want, rel=1e-4)


def test_snap_unique_and_too_many() -> None:
    cands = Candidates(fibonacci_cap(10), None, None)
    idx = snap_unique(np.repeat([[0.0, 0.0, 1.0]], 4, axis=0), cands)
    assert len(set(idx.tolist())) == 4
    with pytest.raises(ScheduleError, match="only 10"):
        snap_unique(fibonacci_cap(11), cands)


def test_arm_candidates_respect_reach_and_keep_out() -> None:
    arm = ArmGeometry(10.0, 75.0, 20.0, 0.0, 45.0)
    cands = candidates_for(arm, 15.0, extra=np.array([[0.0, 0.0, 1.0]]))
    assert len(cands) > 50 and cands.leds is None
    for d in cands.directions:
        assert arm.unreachable_reason(d) is None
        assert np.degrees(np.arcsin(d[2])) >= 15.0 - 1e-9


def test_kmeans_lights_follow_the_cluster_centres() -> None:
    """Paper, Methodology/Fig. 3: light = the centre's intersection with the hemisphere."""
    rng = np.random.default_rng(1)
    a, b = direction_from_az_el(0.0, 60.0), direction_from_az_el(180.0, 60.0)
    pts = np.concatenate(
        [a + 0.02 * rng.normal(size=(500, 3)), b + 0.02 * rng.normal(size=(300, 3))]
    )
    pts /= np.linalg.norm(pts, axis=1, keepdims=True)
    res = cluster_normals(pts, 2)
    got = sorted(res.centres.tolist(), key=lambda c: c[0])
    assert float(angle_between_deg(got[0], b)) < 2.0
    assert float(angle_between_deg(got[1], a)) < 2.0
    assert sorted(res.shares.tolist()) == pytest.approx([0.375, 0.625])
    arm = ArmGeometry(5.0, 85.0, 5.0, 0.0, 45.0)
    idx, _ = plan_kmeans(pts, 2, candidates_for(arm))
    dirs = candidates_for(arm).directions[idx]
    assert min(float(angle_between_deg(d, a)) for d in dirs) < 10.0  # candidate spacing ~13°
    assert min(float(angle_between_deg(d, b)) for d in dirs) < 10.0  # candidate spacing ~13°


def test_kmeans_with_fewer_distinct_normals_than_lights() -> None:
    pts = np.repeat([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]], [30, 10], axis=0)
    res = cluster_normals(pts, 5)
    assert res.distinct_normals == 2 and len(res.centres) == 2
    targets = kmeans_targets(res, 5)
    assert len(targets) == 5
    # repeats follow the pixel shares: the zenith cluster (75 %) is repeated first
    assert np.allclose(targets[2], [0, 0, 1])
