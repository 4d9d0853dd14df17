"""The fast `optimal` planner against its slow reference: same objective, plans as good.

The speed-ups (identical pixels scored once, rank-one swap scans, a sweep-gain stop) must not
change what is optimised: these tests pin the fast path's costs to the direct evaluation on
every pixel, and the fast exchange search's result to the slow search's on small cases.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import said
from threadpoolctl import threadpool_limits

from rti_rig.core.geometry import direction_from_az_el, fibonacci_cap
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner import rank_one
from rti_rig.planner.make_plan import _candidates_and_starts, _held_out_lights, plan_with_report
from rti_rig.planner.objectives import (
    MAX_ERR2,
    NOISE_REL,
    Candidates,
    NormalsObjective,
    SurfaceSample,
    candidates_for,
    cast_shadow_visibility,
    merge_identical_pixels,
)
from rti_rig.planner.optimal import exchange_search
from rti_rig.planner.surface_estimate import estimate_surface, flat_surface, sample_surface
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene


class SlowReference:
    """The planner as it was: every pixel its own row, every swap scanned directly."""

    def __init__(self, sample: SurfaceSample, cands: Candidates, gain_rel: float = 0.0) -> None:
        self.obj = NormalsObjective(sample, cands, gain_rel=gain_rel, merge_pixels=False)

    def cost(self, chosen: np.ndarray) -> float:
        return self.obj.cost(chosen)

    def swap_costs(self, chosen: np.ndarray, position: int, exact: bool = False) -> np.ndarray:
        return self.obj.swap_costs(chosen, position, exact=True)


def relief_preview(seed: int = 0) -> np.ndarray:
    scene = relief_scene(48, 64, seed=seed)
    return lambert_radiance(scene, direction_from_az_el(30.0, 50.0)).astype(np.float32)


def planning_problem(geometry: DomeGeometry | ArmGeometry, n: int, surface, material="auto"):
    cands, starts = _candidates_and_starts(geometry, n, 0.0, 90.0)
    held = _held_out_lights(cands, (0.0, 90.0), False)
    return cands, starts, sample_surface(surface, cands, held, material=material)


DOME = DomeGeometry(fibonacci_cap(60, 5.0), tuple(f"led_{i:02d}" for i in range(60)))
ARM = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)


@pytest.mark.parametrize(
    ("geometry", "n", "relief", "material"),
    [
        (DOME, 6, False, "auto"),
        (DOME, 9, True, "auto"),
        (DOME, 12, True, "glossy"),
        (ARM, 8, True, "auto"),
        (ARM, 12, False, "glossy"),
    ],
)
def test_fast_plan_is_as_good_as_the_slow_reference(geometry, n, relief, material) -> None:
    """The fast search's objective is within 1 % of, or better than, the slow search's, and
    its reported cost is the slow objective's cost of the same lights."""
    surface = estimate_surface(relief_preview(), (30.0, 50.0)) if relief else flat_surface()
    cands, starts, sample = planning_problem(geometry, n, surface, material)
    fast_obj = NormalsObjective(sample, cands)
    slow = SlowReference(sample, cands)
    with threadpool_limits(limits=1):
        fast = exchange_search(fast_obj, starts)
        ref = exchange_search(slow, starts, min_gain=0.0)  # type: ignore[arg-type]
    assert fast.cost == pytest.approx(slow.cost(fast.chosen), rel=1e-9)
    assert fast.cost <= ref.cost * 1.01
    assert fast.cost < fast.start_cost  # it did optimise: a broken scan would stay put


def test_merged_pixels_give_the_same_costs_and_scans() -> None:
    """A level surface's 1792 sampled rows collapse to its 7 distinct normals, same costs."""
    cands = candidates_for(DOME)
    sample = sample_surface(flat_surface(), cands, fibonacci_cap(60, 5.0, 90.0))
    merged = NormalsObjective(sample, cands)
    every = NormalsObjective(sample, cands, merge_pixels=False)
    assert merged.outer.shape[-1] == 7 and every.outer.shape[-1] == len(sample.normals)
    assert merged.n_bias == 1
    chosen = np.array([1, 7, 15, 22, 31, 40, 47, 58])
    assert merged.cost(chosen) == pytest.approx(every.cost(chosen), rel=1e-12)
    for pos in (0, 5):
        assert merged.swap_costs(chosen, pos) == pytest.approx(
            every.swap_costs(chosen, pos, exact=True), rel=1e-9
        )


def test_merge_keeps_first_appearance_order_and_sums_weights() -> None:
    normals = np.array([[0, 0, 1.0], [0, 1.0, 0], [0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0]])
    w = np.array([[1.0, 2.0], [3.0, 4.0], [1.0, 2.0], [5.0, 6.0], [3.0, 4.0]])
    rows, wts, first = merge_identical_pixels(normals, w, np.full(5, 0.2), n_first=3)
    assert rows.tolist() == [0, 1, 3]
    assert wts == pytest.approx([0.4, 0.4, 0.2])
    assert first == pytest.approx([2 / 3, 1 / 3])  # among the first 3 pixels


def test_rank_one_scan_equals_direct_scan_with_ill_lit_pixels() -> None:
    """Pixels steeply tilted away see few of 4 lights: removing one leaves them singular, so
    the direct fallback is exercised; every candidate's cost still equals the direct one."""
    cands = Candidates(fibonacci_cap(40, 5.0, 88.0), None, None)
    rng = np.random.default_rng(3)
    az, el = rng.uniform(0, 360, 60), rng.uniform(5, 90, 60)
    normals = direction_from_az_el(az, el)
    lit = (rng.random((60, 40)) > 0.3).astype(np.float64)  # cast shadows
    sample = SurfaceSample(
        normals, rng.uniform(0.5, 1.5, 60), lit, fibonacci_cap(30, 5, 90), np.ones((60, 30)), 0.3
    )
    obj = NormalsObjective(sample, cands, gain_rel=0.05)
    chosen = np.array([0, 9, 21, 33])
    saw_bad = False
    for pos in range(4):
        fast = obj.swap_costs(chosen, pos)
        exact = obj.swap_costs(chosen, pos, exact=True)
        assert fast == pytest.approx(exact, rel=1e-7)
        base = obj.outer[:, chosen].sum(axis=1) - obj.outer[:, chosen[pos]]
        res = rank_one.scan(
            base, obj.w_kp, obj.dirs, obj.l6, obj.n, obj.wts, NOISE_REL**2, MAX_ERR2, None
        )
        saw_bad = saw_bad or len(res.bad) > 0
    assert saw_bad


def test_skipped_shadow_marches_change_nothing() -> None:
    """A light that climbs above the highest terrain in one step is not marched: the map is
    the same as marching it (low relief: most lights skipped; high relief: few)."""
    rng = np.random.default_rng(1)
    for scale in (0.3, 20.0):
        h = np.cumsum(np.cumsum(rng.normal(size=(40, 40)), 0), 1)
        h = scale * (h - h.min()) / np.ptp(h)
        rows, cols = rng.integers(0, 40, 200), rng.integers(0, 40, 200)
        d = fibonacci_cap(120, 0.0, 90.0)
        got = cast_shadow_visibility(h, rows, cols, d)
        # the march itself, for every light
        want = np.ones_like(got)
        t = np.arange(1, 33, dtype=np.float64)
        for k, (x, y, z) in enumerate(d):
            horiz = np.hypot(x, y)
            cc = np.rint(cols[:, None] + t * x / horiz).astype(int)
            rr = np.rint(rows[:, None] - t * y / horiz).astype(int)
            inside = (cc >= 0) & (cc < 40) & (rr >= 0) & (rr < 40)
            hh = h[np.clip(rr, 0, 39), np.clip(cc, 0, 39)]
            ray = h[rows, cols][:, None] + t * z / horiz
            want[:, k] = ~np.any(inside & (hh > ray + 0.5), axis=1)
        assert np.array_equal(got, want)


def test_arm_reachability_vectorised_matches_the_reason() -> None:
    arm = ArmGeometry(12.0, 70.0, 15.0, 0.0, 45.0, -120.0, 150.0)
    d = np.concatenate([fibonacci_cap(800, 0.0, 90.0), -fibonacci_cap(20, 0.0, 90.0)])
    assert arm.reachable(d).tolist() == [arm.unreachable_reason(x) is None for x in d]


def test_a_hundred_light_plan_on_the_arm_and_a_large_dome() -> None:
    """The sizes the planning-time benchmark times: 100 lights, no preview, both rigs."""
    dome = DomeGeometry(fibonacci_cap(200, 5.0), tuple(f"led_{i:03d}" for i in range(200)))
    for geometry in (dome, ARM):
        sched, report = plan_with_report(None, geometry, 100, "optimal", "normals")
        assert len(sched.steps) == 100
        assert report.expected["optimal"] <= min(
            v for k, v in report.expected.items() if k != "optimal"
        )


def test_scans_among_the_unused_candidates_equal_full_scans() -> None:
    """The exchange search scores only the unused candidates; on those the costs are the full
    scan's, elsewhere inf (many pixel rows: the pool's arrays are gathered; few: masked)."""
    cands = Candidates(fibonacci_cap(40, 5.0, 88.0), None, None)
    rng = np.random.default_rng(5)
    for rows in (80, 3):
        normals = direction_from_az_el(rng.uniform(0, 360, rows), rng.uniform(5, 90, rows))
        lit = (rng.random((rows, 40)) > 0.3).astype(np.float64)
        sample = SurfaceSample(
            normals, np.ones(rows), lit, fibonacci_cap(30, 5, 90), np.ones((rows, 30)), 0.3
        )
        obj = NormalsObjective(sample, cands)
        chosen = np.array([0, 9, 21, 33, 38])
        among = np.setdiff1d(np.arange(40), chosen)
        for exact in (False, True):
            full = obj.swap_costs(chosen, 2, exact=exact)
            part = obj.swap_costs(chosen, 2, exact=exact, among=among)
            assert part[among] == pytest.approx(full[among], rel=1e-9)
            assert np.all(np.isinf(np.delete(part, among)))


@pytest.mark.e2e
@pytest.mark.slow
def test_cli_plans_a_hundred_lights_on_the_shipped_arm_and_a_large_bare_lp(tmp_path) -> None:
    """Through the front door: `plan --method optimal --lights 100` on the shipped simulated
    arm and on a 200-LED dome given as a bare .lp (no shipped dome has 100 LEDs)."""
    from typer.testing import CliRunner

    from rti_rig.cli import app
    from rti_rig.core.lp_format import read_lp

    repo = Path(__file__).resolve().parents[2]
    dirs = fibonacci_cap(200, 5.0)
    lp = tmp_path / "dome200.lp"
    lp.write_text(
        "200\n" + "".join(f"led_{i:03d}.jpg {x:.6f} {y:.6f} {z:.6f}\n" for i, (x, y, z) in
                          enumerate(dirs))
    )  # fmt: skip
    runner = CliRunner()
    for rig in (repo / "rig_configs" / "simulated_arm.toml", lp):
        out = tmp_path / f"{rig.stem}_plan.lp"
        args = ["plan", "--rig", str(rig), "--lights", "100", "--method", "optimal"]
        r = runner.invoke(app, [*args, "--out", str(out)])
        assert r.exit_code == 0, r.output
        assert "optimal" in r.output
        assert len(read_lp(out)) == 100


@pytest.mark.parametrize(
    "arm",
    [ARM, ArmGeometry(5.0, 85.0, 5.0, 0.0, 45.0), ArmGeometry(20.0, 70.0, 20.0, 0.0, 30.0)],
)
@pytest.mark.parametrize("n", [6, 12, 36])
def test_arm_starting_layouts_are_the_candidates_they_index(arm, n):
    """The homogeneous starts are indexed by position in the arm's candidate set, so the set
    must hold each start's directions at those positions (the reachability filter now applies
    to the dense band only; a start direction it dropped would shift every later index)."""
    cands, starts = _candidates_and_starts(arm, n, 0.0, 90.0)
    for label, idx in starts:
        floor = float(label.split("≥")[1].rstrip("°"))
        np.testing.assert_array_equal(cands.directions[idx], arm.homogeneous(n, floor))
        assert arm.reachable(cands.directions[idx]).all()


def test_an_unreachable_start_is_left_out_not_shifting_the_others():
    """A start layout the reachability filter rejects (here: one direction of the second
    start, as rounding on the keep-out cone's edge could) must not shift later indices."""
    first = _candidates_and_starts(ARM, 12, 0.0, 90.0)[1]
    assert len(first) >= 3
    rejected = ARM.homogeneous(12, float(first[1][0].split("≥")[1].rstrip("°")))[0]

    class Picky(ArmGeometry):
        def reachable(self, directions):
            d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
            return super().reachable(d) & ~np.all(np.isclose(d, rejected), axis=1)

    arm = Picky(5.0, 80.0, 10.0, 0.0, 45.0)
    cands, starts = _candidates_and_starts(arm, 12, 0.0, 90.0)
    assert [label for label, _ in starts] == [first[0][0]] + [lab for lab, _ in first[2:]]
    for label, idx in starts:
        floor = float(label.split("≥")[1].rstrip("°"))
        np.testing.assert_array_equal(cands.directions[idx], arm.homogeneous(12, floor))


@pytest.mark.e2e
def test_cli_plans_a_hundred_arm_lights_from_a_preview(tmp_path) -> None:
    """Through the front door, from a preview (16-bit PNG: linear) on the shipped virtual arm:
    100 distinct reachable lights, the binned search reported, its plan cheaper on every pixel
    than each homogeneous start, and the same lights as the library's plan."""
    import cv2
    from typer.testing import CliRunner

    from rti_rig.app.config import load_rig_config, rig_geometry
    from rti_rig.cli import app
    from rti_rig.core.lp_format import read_lp

    repo = Path(__file__).resolve().parents[2]
    scene = relief_scene(96, 128, seed=0)
    image = lambert_radiance(scene, direction_from_az_el(30.0, 50.0))
    png = tmp_path / "preview.png"
    cv2.imwrite(str(png), np.round(image / image.max() * 65535).astype(np.uint16)[..., ::-1])
    out = tmp_path / "plan.lp"
    rig = repo / "rig_configs" / "virtual_arm.toml"
    args = ["plan", str(png), "--rig", str(rig), "--lights", "100", "--method", "optimal"]
    r = CliRunner().invoke(app, [*args, "--preview-light", "30,50", "--out", str(out)])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "searched on" in text and "binned pixel rows of 1792" in text
    expected = text.split("expected RMS normal error (degrees): ")[1].split(" searched")[0]
    costs = dict(part.rsplit(" ", 1) for part in expected.split(", "))
    assert set(costs) > {"optimal", "uniform ≥0°"}
    assert all(float(costs["optimal"]) < float(v) for k, v in costs.items() if k != "optimal")
    got = np.array([e.direction for e in read_lp(out)])
    assert len(got) == 100 and len(np.unique(got.round(6), axis=0)) == 100
    geometry = rig_geometry(load_rig_config(rig))
    assert geometry.reachable(got).all()
    preview = cv2.cvtColor(cv2.imread(str(png), cv2.IMREAD_UNCHANGED), cv2.COLOR_BGR2RGB)
    sched, _ = plan_with_report(preview, geometry, 100, "optimal", "normals", (30.0, 50.0))
    want = np.array([s.direction for s in sched.steps])
    dist = np.linalg.norm(got[:, None] - want[None], axis=-1)  # the .lp rounds to 1e-6
    assert np.all(dist.min(axis=1) < 1e-5) and np.all(dist.min(axis=0) < 1e-5)


def test_single_precision_scans_are_within_a_millionth_of_the_exact_costs() -> None:
    """A preview's pooled scan runs in single precision (it differs from the double one) and
    stays within 1e-6 of the direct evaluation for every candidate, bias term included."""
    cands, starts, sample = planning_problem(ARM, 36, estimate_surface(relief_preview(), (30, 50)))
    obj = NormalsObjective(sample, cands)
    chosen = starts[0][1]
    among = np.setdiff1d(np.arange(len(cands)), chosen)
    with threadpool_limits(limits=1):
        for pos in (0, 17, 35):
            single = obj.swap_costs(chosen, pos, among=among)
            double = obj.swap_costs(chosen, pos, among=among, single=False)
            exact = obj.swap_costs(chosen, pos, among=among, exact=True)
            assert not np.array_equal(single[among], double[among])  # the fast path ran
            assert single[among] == pytest.approx(exact[among], rel=1e-6)
            assert double[among] == pytest.approx(exact[among], rel=1e-9)


def test_a_proposal_the_exact_cost_rejects_is_rescanned_in_double_then_exactly() -> None:
    """The scan levels of the normals objective in order: single precision, double, direct."""
    calls: list[dict] = []

    class Ladder:
        scan_levels = NormalsObjective.scan_levels
        candidate_count = 10

        def cost(self, chosen: np.ndarray) -> float:
            return float(np.sum(chosen))

        def swap_costs(self, chosen, position, exact=False, among=None, single=True):
            calls.append({"exact": exact, "single": single})
            if not exact:  # both fast levels promise a swap that is no gain
                out = np.full(10, np.inf)
                out[9] = -1.0
                return out
            return np.array([float(np.sum(chosen) - chosen[position] + k) for k in range(10)])

    res = exchange_search(Ladder(), [("start", np.array([4, 5, 6]))], max_passes=1)  # type: ignore[arg-type]
    assert calls[:3] == [
        {"exact": False, "single": True},
        {"exact": False, "single": False},
        {"exact": True, "single": True},
    ]
    assert sorted(res.chosen.tolist()) == [0, 1, 2]


def test_the_search_stops_once_every_position_is_known_to_have_no_improving_swap() -> None:
    """After the last accepted swap, the search scans each other position once more and stops:
    not the rest of that sweep and a whole confirming sweep after it. Its plan is a local
    optimum for single swaps (checked by direct evaluation) all the same."""
    surface = estimate_surface(relief_preview(), (30.0, 50.0))
    cands, starts, sample = planning_problem(DOME, 12, surface)
    obj = NormalsObjective(sample, cands)
    seen: list[tuple[int, bytes]] = []

    class Counting:
        candidate_count = obj.candidate_count
        scan_levels = obj.scan_levels

        def cost(self, chosen: np.ndarray) -> float:
            return obj.cost(chosen)

        def swap_costs(self, chosen, position, **kw) -> np.ndarray:
            seen.append((position, np.asarray(chosen).tobytes()))
            return obj.swap_costs(chosen, position, **kw)

    with threadpool_limits(limits=1):
        res = exchange_search(Counting(), starts, min_gain=0.0)  # type: ignore[arg-type]
    assert res.swaps > 0
    final = res.chosen.tobytes()
    first_final = next(i for i, (_, layout) in enumerate(seen) if layout == final)
    # the scan that found the last swap saw the layout before it; after it, n - 1 positions
    after = {pos for pos, _ in seen[first_final:]}
    assert len(after) == len(seen[first_final:]) == 11
    assert seen[first_final - 1][0] not in after
    unused = np.setdiff1d(np.arange(len(cands)), res.chosen)
    for pos in range(12):
        trial = obj.swap_costs(res.chosen, pos, exact=True, among=unused)
        assert trial[unused].min() >= res.cost * (1 - 1e-9)
