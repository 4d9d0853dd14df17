"""The bounded swap scan: candidates proved unable to beat the cost are skipped, and nothing else
changes.

`rank_one.scan(..., below=...)` runs its (candidates × pixels) passes only on the candidates
whose lower bound is under ``below``. These tests pin what makes that exact: the bounds hold
(the variance reduction's upper bound, the bias term's lower bound), every candidate it scores
gets the value the full scan gives it bit for bit (the passes on a subset of rows round as on
all rows), every candidate it skips scores at least ``below`` in the full scan, and so the
exchange search — and the `.lp` the command line writes — are the same with or without it.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from threadpoolctl import threadpool_limits
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import direction_from_az_el, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner import objectives, rank_one
from rti_rig.planner.make_plan import _candidates_and_starts, _held_out_lights
from rti_rig.planner.objectives import MAX_ERR2, NormalsObjective
from rti_rig.planner.optimal import exchange_search
from rti_rig.planner.surface_estimate import estimate_surface, sample_surface
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

DOME = DomeGeometry(fibonacci_cap(80, 5.0), tuple(f"led_{i:02d}" for i in range(80)))
ARM = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)


def problem(geometry: DomeGeometry | ArmGeometry, n: int, seed: int, light=(30.0, 50.0)):
    """The normals objective of a relief preview (many distinct pixel rows: the pooled,
    single-precision scan) and the planner's starting layouts."""
    scene = relief_scene(48, 64, seed=seed)
    preview = lambert_radiance(scene, direction_from_az_el(*light)).astype(np.float32)
    cands, starts = _candidates_and_starts(geometry, n, 0.0, 90.0)
    held = _held_out_lights(cands, (0.0, 90.0), False)
    sample = sample_surface(estimate_surface(preview, light), cands, held)
    return NormalsObjective(sample, cands), starts


CASES = [(ARM, 36, 0), (ARM, 20, 3), (DOME, 24, 1), (DOME, 40, 2)]


@pytest.fixture(autouse=True)
def bound_every_scan(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> None:
    """These small problems are bounded and batched too (the planner does so only for large
    scans and many lights)."""
    if "shipped" not in request.node.name:
        monkeypatch.setattr(rank_one, "BOUNDED_MIN_WORK", 0)
        monkeypatch.setattr(objectives, "INVERSE_BATCH_MIN_LIGHTS", 0)


def layouts(obj: NormalsObjective, starts, seed: int):
    """The first start and two random layouts of the same size."""
    rng = np.random.default_rng(seed)
    first = np.asarray(starts[0][1], dtype=np.intp)
    yield first
    for _ in range(2):
        yield rng.choice(obj.candidate_count, len(first), replace=False).astype(np.intp)


@pytest.mark.parametrize(("geometry", "n", "seed"), CASES)
def test_a_bounded_scan_scores_as_the_full_scan_and_skips_only_what_cannot_win(
    geometry, n: int, seed: int
) -> None:
    obj, starts = problem(geometry, n, seed)
    pruned = partial = 0
    with threadpool_limits(limits=1):
        for chosen in layouts(obj, starts, seed):
            among = np.setdiff1d(np.arange(obj.candidate_count), chosen)
            cost = obj.cost(chosen)
            for pos in (0, n // 2, n - 1):
                full = obj.swap_costs(chosen, pos, among=among)
                ranked = np.sort(full[among])
                # the search's own threshold, a few quantiles (many candidates scored) and
                # one between the best two (one or a few scored)
                for below in (
                    cost * (1 - 1e-9),
                    *np.quantile(ranked, [0.05, 0.5, 0.95]),
                    0.5 * (ranked[0] + ranked[1]),
                ):
                    got = obj.swap_costs(chosen, pos, among=among, below=float(below))
                    scored = np.isfinite(got)
                    assert np.array_equal(got[scored], full[scored])  # bit for bit
                    assert np.all(full[~scored] >= below)
                    assert np.all(scored[among] | (full[among] >= below))
                    k = int(np.count_nonzero(scored))
                    pruned += k < len(among)
                    partial += 0 < k < len(among)
    assert pruned and partial  # both paths ran


@pytest.mark.parametrize(("geometry", "n", "seed"), CASES)
def test_the_bounds_hold_on_every_candidate(geometry, n: int, seed: int) -> None:
    """The variance reduction's bound is above what the passes compute, the bias term's below,
    for every candidate, position and layout tried."""
    obj, starts = problem(geometry, n, seed)
    f32 = np.float32
    checked = 0
    for chosen in layouts(obj, starts, seed):
        among = np.setdiff1d(np.arange(obj.candidate_count), chosen)
        total_m, total_r = obj._information(chosen), obj._cross_sum(chosen)
        for pos in range(0, n, max(1, n // 6)):
            out = chosen[pos : pos + 1]
            base = total_m - obj._outer_at(out, slice(None))[:, 0]
            rb = total_r - obj._cross_at(out, slice(None))[:, 0]
            inv6, ratio = rank_one._inverse_and_condition(base)
            if not np.all(ratio > rank_one.SINGLE_CONDITIONED):
                continue  # the bounds serve the scans where every pixel is well conditioned
            checked += 1
            inv6 = inv6 / ratio
            _, c6 = rank_one._projected_inverse(inv6, obj.n)
            w32 = obj.w_kp[among].astype(f32)
            args = (obj.l6[among].astype(f32), inv6.astype(f32), (c6 * obj.wts).astype(f32), w32)
            red = rank_one._reduction(*args)
            w_max = float(w32.max())
            assert np.all(rank_one._variance_bound(*args, 1.0, w_max) >= red)
            crude = rank_one._variance_bound(*args[:3], None, 1.0, w_max)
            assert np.all(crude >= red)
            nb = obj.n_bias
            bias = rank_one.BiasTerms(rb, obj.g_all, obj.hsh[among], obj.wts_bias, obj.tau2)
            prep = rank_one._bias_prep(inv6[:, :nb], c6[:, :nb], obj.n[:nb], bias, np.arange(nb))
            forms_in, h2 = rank_one.candidate_forms(obj.dirs[among], obj.hsh[among], obj.l6[among])
            wb = obj.w_kp[among, :nb]
            exact = rank_one._bias_chain(
                prep, forms_in, h2, obj.l6[among], wb, obj.tau2, obj.wts_bias, MAX_ERR2, True
            )
            low = rank_one._bias_bound(
                prep, forms_in, h2, wb, obj.tau2, obj.wts_bias, MAX_ERR2, 1.0, w_max
            )
            assert low is not None and np.all(low <= exact)
            # a subset of rows (one row is scored among two): the whole call's values, bit
            # for bit
            for rows in (np.arange(1, len(among), 7), rank_one._two_rows(np.array([5]))):
                part = rank_one._bias_chain(
                    prep, forms_in, h2, obj.l6[among], wb, obj.tau2, obj.wts_bias, MAX_ERR2,
                    True, rows=rows,
                )  # fmt: skip
                assert np.array_equal(part, exact[rows])
                sub = rank_one._reduction(args[0][rows], args[1], args[2], w32[rows])
                assert np.array_equal(sub, red[rows])
    assert checked >= 6


class Unbounded:
    """The same objective without ``bounded_scans``: the search scores every candidate."""

    def __init__(self, obj: NormalsObjective) -> None:
        self.obj = obj
        self.candidate_count = obj.candidate_count
        self.scan_levels = obj.scan_levels

    def cost(self, chosen: np.ndarray) -> float:
        return self.obj.cost(chosen)

    def swap_costs(self, chosen: np.ndarray, position: int, **kw) -> np.ndarray:
        assert "below" not in kw
        return self.obj.swap_costs(chosen, position, **kw)


@pytest.mark.parametrize(("geometry", "n", "seed"), CASES)
def test_the_search_makes_the_same_swaps_with_and_without_the_bounds(
    geometry, n: int, seed: int
) -> None:
    obj, starts = problem(geometry, n, seed)
    calls: list[float] = []
    with threadpool_limits(limits=1):
        plain = exchange_search(Unbounded(obj), starts, min_gain=0.0)  # type: ignore[arg-type]
        original = obj.swap_costs

        def spy(chosen, position, **kw):
            calls.append(kw.get("below", np.nan))
            return original(chosen, position, **kw)

        obj.swap_costs = spy  # type: ignore[method-assign]
        bounded = exchange_search(obj, starts, min_gain=0.0)
    assert calls and not np.isnan(calls).any()  # the bounded scans ran
    assert plain.swaps > 0
    assert np.array_equal(bounded.chosen, plain.chosen)
    assert bounded.cost == plain.cost and bounded.swaps == plain.swaps


def test_the_shipped_arm_plan_is_the_same_file_with_and_without_the_bounds(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Through the front door: `rti-rig plan PREVIEW --rig rig_configs/simulated_arm.toml
    --lights 100 --method optimal` (its scans bounded) writes the same bytes when the scans
    score every candidate."""
    repo = Path(__file__).resolve().parents[2]
    scene = relief_scene(96, 128, seed=0)
    image = lambert_radiance(scene, direction_from_az_el(30.0, 50.0))
    png = tmp_path / "preview.png"
    cv2.imwrite(str(png), np.round(image / image.max() * 65535).astype(np.uint16)[..., ::-1])
    rig = repo / "rig_configs" / "simulated_arm.toml"

    def plan(out: Path) -> bytes:
        args = ["plan", str(png), "--rig", str(rig), "--lights", "100", "--method", "optimal"]
        r = CliRunner().invoke(app, [*args, "--preview-light", "30,50", "--out", str(out)])
        assert r.exit_code == 0, r.output
        return out.read_bytes()

    seen: list[int] = []
    original = rank_one._variance_bound

    def counted(*args, **kw):
        seen.append(1)
        return original(*args, **kw)

    monkeypatch.setattr(rank_one, "_variance_bound", counted)
    bounded = plan(tmp_path / "bounded.lp")
    assert seen  # the shipped arm's scans were bounded
    monkeypatch.setattr(NormalsObjective, "bounded_scans", False)
    assert plan(tmp_path / "plain.lp") == bounded


@pytest.mark.parametrize(("geometry", "n", "seed"), CASES[:2])
def test_the_inverses_of_a_batch_of_positions_are_those_of_each_alone(
    geometry, n: int, seed: int
) -> None:
    """The scans' per-pixel inverses are computed for several positions at once: bit for bit
    what each position gets alone, ill-conditioned pixels included."""
    obj, starts = problem(geometry, n, seed)
    rng = np.random.default_rng(seed)
    for chosen in layouts(obj, starts, seed):
        total = obj._information(chosen)
        lights = chosen[: min(7, n)]
        batch = total[:, None, :] - obj._outer_at(lights, slice(None))
        # a few pixels made singular and nearly so
        batch[:, :, :3] = 0.0
        batch[:, :, 3:6] *= rng.uniform(0.0, 1e-9, size=(1, 1, 3))
        got = rank_one.inverses(batch, obj.n)
        for j in range(len(lights)):
            alone = rank_one.inverses(np.ascontiguousarray(batch[:, j]), obj.n)
            for a, b in zip(got, alone, strict=True):
                assert np.array_equal(a[:, j] if a.ndim == 3 else a[j], b, equal_nan=True)
        among = np.setdiff1d(np.arange(obj.candidate_count), chosen)
        cost = obj.cost(chosen)
        for pos in (0, 1, n - 1):  # through the objective: batched and recomputed alike
            batched = obj.swap_costs(chosen, pos, among=among, below=cost)
            obj._inverse_batch = None
            fresh = obj.swap_costs(chosen, pos, among=among, below=cost)
            obj._inverse_batch = None
            assert np.array_equal(batched, fresh)


@pytest.mark.parametrize(("geometry", "n", "seed"), CASES)
def test_the_bias_terms_of_a_batch_of_positions_are_those_of_each_alone(
    geometry, n: int, seed: int
) -> None:
    """The bias term's per-pixel coefficients, computed for several positions at once, are bit
    for bit those each position's scan computes alone."""
    obj, starts = problem(geometry, n, seed)
    nb = obj.n_bias
    checked = 0
    for chosen in layouts(obj, starts, seed):
        total_m, total_r = obj._information(chosen), obj._cross_sum(chosen)
        lights = chosen[: min(9, n)]
        base = total_m[:, None, :] - obj._outer_at(lights, slice(None))
        inv = rank_one.inverses(base, obj.n)
        if not np.all(inv[1][:, :nb] > rank_one.WELL_CONDITIONED):
            continue
        every = np.arange(nb)
        rb = total_r[:, None] - obj._cross_at(lights, slice(None))
        batch = rank_one.bias_prep_batch(
            inv[0][:, :, every], inv[3][:, :, every], obj.n[every], rb[:, :, every],
            obj.g_all[:, every],
        )  # fmt: skip
        for j, light in enumerate(lights):
            base_j = total_m - obj._outer_at(light[None], slice(None))[:, 0]
            inv6, _, _, c6 = rank_one.inverses(base_j, obj.n)
            rb_j = total_r - obj._cross_at(light[None], slice(None))[:, 0]
            bias = rank_one.BiasTerms(rb_j, obj.g_all, obj.hsh, obj.wts_bias, obj.tau2)
            alone = rank_one._bias_prep(inv6[:, every], c6[:, every], obj.n[every], bias, every)
            for field in ("c0", "coef", "quad", "trace", "g_norm"):
                assert np.array_equal(getattr(batch[j], field), getattr(alone, field)), field
            checked += 1
    assert checked >= len(lights)
