"""The hedged starting layouts that benchmarks/adaptive_reach.py measures: 4 lights of the
default floor's homogeneous layout (so the default design stays exactly that layout), as many
as possible shared with the other floors' layouts."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.adaptive_reach import hedged_start, shared_three_start, start_functions
from rti_rig.app.usecases.adaptive import dome_start
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.adaptive import DESIGN_DEFAULT_FLOOR
from rti_rig.planner.uniform import select_uniform_leds


def _dome(seed: int) -> DomeGeometry:
    cand = fibonacci_cap(240, 0.0, 90.0)
    keep = np.sort(np.random.default_rng(seed).choice(240, 216, replace=False))
    return DomeGeometry(cand[keep], tuple(f"c{i:03d}" for i in keep))


@pytest.mark.parametrize("n", [6, 9, 12, 18])
@pytest.mark.parametrize("seed", [0, 1])
def test_a_hedged_start_is_part_of_the_default_layout_and_shares_more(n: int, seed: int) -> None:
    dome = _dome(seed)
    default = {int(i) for i in select_uniform_leds(dome, n, DESIGN_DEFAULT_FLOOR)}
    partner = {int(i) for i in select_uniform_leds(dome, n, 20.0)}
    plain = dome_start(dome, 4, n)
    hedged = hedged_start(dome, 4, n, (20.0,))
    assert len(set(hedged)) == 4
    assert set(hedged) <= default
    assert len(set(hedged) & partner) >= len(set(plain) & partner)
    assert len(set(hedged) & partner) == min(4, len(default & partner))


def test_the_default_start_is_what_ships() -> None:
    dome = _dome(0)
    assert start_functions()["default"](dome, 4, 9) == dome_start(dome, 4, 9)


@pytest.mark.parametrize("n", [6, 9, 12, 18])
def test_the_three_light_start_belongs_to_both_layouts_or_is_the_shipped_one(n: int) -> None:
    dome = _dome(0)
    default = {int(i) for i in select_uniform_leds(dome, n, DESIGN_DEFAULT_FLOOR)}
    partner = {int(i) for i in select_uniform_leds(dome, n, 20.0)}
    start = shared_three_start(dome, 4, n)
    if len(default & partner) >= 3:
        assert len(start) == 3
        assert set(start) <= default & partner
    else:
        assert start == dome_start(dome, 4, n)


@pytest.mark.parametrize("n", [6, 9])
def test_a_completion_towards_a_layout_keeps_the_start_and_the_layout_s_other_lights(
    n: int,
) -> None:
    from benchmarks.adaptive_reach import layout_completion

    dome = _dome(0)
    layout = select_uniform_leds(dome, n, 20.0)
    start = dome_start(dome, 4, n)
    rest = layout_completion(dome.directions, layout, start)
    assert len(rest) == n - 4 and not set(rest.tolist()) & set(start)
    assert len(set(rest.tolist())) == n - 4
    # a start inside the layout: the completion is the layout's other lights
    inside = [int(i) for i in layout[:4]]
    assert sorted(layout_completion(dome.directions, layout, inside).tolist()) == sorted(
        int(i) for i in layout[4:]
    )


def test_optimal_pinned_keeps_the_lights_shot() -> None:
    from benchmarks.adaptive_reach import pinned_optimal

    dome = _dome(1)
    start = dome_start(dome, 4, 9)
    got = pinned_optimal(None, dome, 9, None, start)  # type: ignore[arg-type]
    assert len(got) == 9 == len(set(got.tolist())) and set(start) <= set(got.tolist())


def test_the_true_error_ceiling_is_never_worse_than_its_start() -> None:
    from benchmarks.adaptive_reach import _true_greedy

    target = np.linspace(0.0, 1.0, 30)

    def err(idx: np.ndarray) -> float:  # a toy error: distance of the lights' mean from 0.2
        return abs(float(target[idx].mean()) - 0.2)

    keep = np.arange(30)
    avail = np.ones(30, bool)
    avail[[0, 1]] = False
    start = np.array([20, 25, 29])
    got = _true_greedy(err, keep, np.array([0, 1]), start, avail)
    assert got <= err(keep[np.r_[[0, 1], start]])
    assert got < 0.05  # the exchange found the low lights


@pytest.mark.parametrize("objective", ["normals", "relight"])
@pytest.mark.parametrize("n", [6, 9, 12, 18])
def test_the_start_variants_are_the_two_rules_whatever_the_objective(
    n: int, objective: str
) -> None:
    """``above-floor`` (what ships for relighting) keeps every starting light at or above
    START_FLOOR_DEG, ``all-lights`` (what ships for normals) took one below it on this dome;
    both are 4 lights of the default layout (its design stays reachable), and ``default`` is
    whichever ships for the objective."""
    from benchmarks.adaptive_reach import above_floor_start, all_lights_start
    from rti_rig.planner.adaptive import START_ABOVE_FLOOR, START_FLOOR_DEG

    dome = _dome(0)
    default = {int(i) for i in select_uniform_leds(dome, n, DESIGN_DEFAULT_FLOOR)}
    above, every = above_floor_start(dome, 4, n, objective), all_lights_start(dome, 4, n, objective)
    assert set(above) <= default and set(every) <= default and len(set(above)) == 4
    el = np.degrees(np.arcsin(dome.directions[:, 2]))
    assert el[every].min() < START_FLOOR_DEG <= el[above].min()
    shipped = above if objective in START_ABOVE_FLOOR else every
    assert dome_start(dome, 4, n, objective) == shipped


def test_the_relight_measure_scores_every_layout_on_lights_none_of_them_took() -> None:
    """``--measure relight``: each layout's fit.rti (as `rti-rig fit` writes it) relit to the
    lights none of the compared layouts took (a layout joining the comparison changes that set,
    not the method); the normals measure scores the same layouts by their normal error."""
    from types import SimpleNamespace

    from benchmarks.adaptive_reach import _layout_scores

    dirs = fibonacci_cap(60, 5.0)
    rng = np.random.default_rng(3)
    albedo = 0.3 + 0.4 * rng.random((12, 12, 3))
    normal = np.array([0.2, 0.1, 1.0]) / np.linalg.norm([0.2, 0.1, 1.0])
    shade = np.maximum(dirs @ normal, 0.0)[:, None, None, None]
    images = (shade * albedo[None]).astype(np.float32)
    data = SimpleNamespace(candidate_images=images, candidate_dirs=dirs)
    score = _layout_scores(data, "relight")
    layouts = {"a": np.arange(0, 60, 10), "b": np.arange(1, 60, 4)}
    got = score(layouts)
    assert set(got) == {"a", "b"} and all(np.isfinite(v) and v > 20.0 for v in got.values())
    from benchmarks.planner_real_data import written_rti_psnr
    from rti_rig.planner.topography import REC709

    lum = images @ REC709.astype(np.float32)
    held = np.setdiff1d(np.arange(60), np.r_[layouts["a"], layouts["b"]])
    a = layouts["a"]
    want = written_rti_psnr(lum[a], dirs[a], lum[held], dirs[held], chosen_on=images[a])[1]
    assert got["a"] == want
    # another layout joining the comparison takes its lights out of everyone's held-out set
    c = np.arange(2, 60, 7)
    more = score({**layouts, "c": c})
    assert set(more) == {"a", "b", "c"}
    held = np.setdiff1d(held, c)
    want = written_rti_psnr(lum[a], dirs[a], lum[held], dirs[held], chosen_on=images[a])[1]
    assert more["a"] == want != got["a"]
    normals = _layout_scores(
        SimpleNamespace(**vars(data), normals=np.broadcast_to(normal, (12, 12, 3))), "normals"
    )
    assert set(normals(layouts)) == {"a", "b"}


def test_a_relight_table_tunes_the_bar_and_the_oracle_to_the_highest_psnr() -> None:
    """``scene_rows``: for normal error the bar is the floor of the lowest mean error and the
    oracle the per-draw minimum, flagged "above the bar"; for relighting PSNR the floor of the
    highest mean PSNR and the per-draw maximum, flagged "below the bar"."""
    from benchmarks.adaptive_reach import FLOORS, NS, scene_rows

    base = {0.0: 20.0, 10.0: 21.0, 20.0: 22.0, 30.0: 23.0}
    res: dict = {}
    for n in NS:
        for f in FLOORS:
            res[(n, f"hom {f:g}")] = [base[f], base[f]]
            # the start's completions: below every homogeneous layout, except one draw at 0°
            res[(n, f"s {f:g}")] = [base[f] - 5.0, base[f] - 5.0]
        res[(n, "s 0")] = [30.0, 10.0]
    psnr = scene_rows("x", res, ["s"], "relight")
    assert all(r.startswith(f"| x | {n} | 30°: 23 |") for r, n in zip(psnr, NS, strict=True))
    # per draw the best of (30, 16, 17, 18) and (10, 16, 17, 18): (30 + 18) / 2 = 24 ≥ 23
    assert all("oracle 24;" in r or r.endswith("oracle 24 |") for r in psnr)
    assert not any("below the bar" in r for r in psnr)
    err = scene_rows("x", res, ["s"], "normals")
    assert all(r.startswith(f"| x | {n} | 0°: 20 |") for r, n in zip(err, NS, strict=True))
    # per draw the lowest: (16 + 10) / 2 = 13 ≤ 20, no flag; a start worse everywhere is flagged
    assert all(r.endswith("oracle 13 |") for r in err)
    for n in NS:
        for f in FLOORS:
            res[(n, f"s {f:g}")] = [base[f] + 1.0, base[f] + 1.0]
    assert all("**above the bar**" in r for r in scene_rows("x", res, ["s"], "normals"))
    assert not any("below the bar" in r for r in scene_rows("x", res, ["s"], "relight"))
    for n in NS:
        for f in FLOORS:
            res[(n, f"s {f:g}")] = [base[f] - 1.0, base[f] - 1.0]
    assert all("**below the bar**" in r for r in scene_rows("x", res, ["s"], "relight"))


def test_the_true_surface_sample_reads_shadows_from_the_images() -> None:
    """A Lambertian pixel lit as its normal says reads fully lit; one darkened to a quarter
    (a cast shadow the normal does not show) reads a quarter; one facing away, unlit."""
    from types import SimpleNamespace

    from benchmarks.adaptive_reach import true_surface_sample

    dirs = fibonacci_cap(12, 10.0, 80.0)
    normals = np.array([[0.0, 0.0, 1.0], [0.3, 0.0, 0.954], [0.0, 0.2, 0.98]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    albedo = np.array([0.8, 0.5, 0.3])
    shade = np.clip(normals @ dirs.T, 0.0, None) * albedo[:, None]  # (P, K)
    shade[1, 3] *= 0.25  # pixel 1 partly shadowed under light 3
    images = np.repeat(shade.T.reshape(12, 1, 3, 1), 3, axis=3).astype(np.float32)
    data = SimpleNamespace(
        normals=normals.reshape(1, 3, 3), candidate_dirs=dirs, candidate_images=images
    )
    sample = true_surface_sample(data, np.arange(12), np.arange(3))
    lit = sample.lit_candidates
    assert lit.shape == (3, 12)
    assert lit[1, 3] == pytest.approx(0.25, abs=1e-5)
    others = np.ones_like(lit, dtype=bool)
    others[1, 3] = False
    assert np.allclose(lit[others], 1.0, atol=1e-5)


def test_the_simulated_search_never_leaves_a_worse_simulated_design() -> None:
    """The exchange on the session's simulated score keeps the lights shot out of the design
    and ends no worse, on that score, than where it began."""
    from benchmarks.adaptive_reach import _simulated_search
    from rti_rig.app.usecases.adaptive import robust_fit
    from rti_rig.planner.adaptive_bias import ObjectModel, simulate_designs

    rng = np.random.default_rng(3)
    n = rng.normal(size=(60, 3)) * [0.3, 0.3, 1.0]
    n[:, 2] = np.abs(n[:, 2]) + 0.5
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    dirs = fibonacci_cap(30, 10.0, 85.0)
    shot = np.array([0, 7, 14, 21])
    model = ObjectModel(  # a matte object without cast shadows
        normals=n,
        albedo=np.full(60, 0.6),
        spec_strength=0.0,
        spec_exponent=1.0,
        noise=0.01,
        shadow_el=np.full((60, 1), -np.inf),
        shadow_az=np.zeros((60, 1)),
        lights=dirs[shot],
        shadowed=np.zeros((60, 4), dtype=bool),
    )
    start = np.array([3, 26])
    full = lambda free: np.concatenate([dirs[shot], dirs[free]])  # noqa: E731
    before = simulate_designs(model, [full(start)], robust_fit)[0]
    out = _simulated_search(model, dirs, shot, start, before, sweeps=1)
    assert len(out) == 2 and not set(out.tolist()) & set(shot.tolist())
    assert simulate_designs(model, [full(out)], robust_fit)[0] <= before + 1e-12


def _relief_preview(light: tuple[float, float]) -> np.ndarray:
    from rti_rig.core.geometry import direction_from_az_el
    from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

    scene = relief_scene(48, 64, seed=0)
    return lambert_radiance(scene, direction_from_az_el(*light)).astype(np.float32)


def test_the_floor_costs_are_optimal_s_own_scores_of_its_homogeneous_starts() -> None:
    from benchmarks.adaptive_reach import FLOORS, floor_costs
    from rti_rig.planner.make_plan import plan_with_report

    dome, light = _dome(0), (30.0, 50.0)
    preview = _relief_preview(light)
    costs = floor_costs(preview, dome, 9, light)
    _, report = plan_with_report(preview, dome, 9, "optimal", "normals", light)
    assert set(costs) == set(FLOORS)
    for f in FLOORS:
        assert costs[f] == pytest.approx(report.expected[f"uniform ≥{f:g}°"])


def test_the_preview_floor_is_the_least_expected_error_and_a_tie_keeps_the_default() -> None:
    from benchmarks.adaptive_reach import preview_floor

    assert preview_floor({0.0: 0.3, 10.0: 0.2, 20.0: 0.1, 30.0: 0.4}, 10.0) == 20.0
    assert preview_floor({0.0: 0.1, 10.0: 0.1, 20.0: 0.1, 30.0: 0.4}, 10.0) == 10.0
    assert preview_floor({0.0: 0.1, 10.0: 0.2, 20.0: 0.1, 30.0: 0.4}, 10.0) == 0.0


@pytest.mark.parametrize("n", [6, 9, 12, 18])
def test_the_preview_floor_start_belongs_to_the_chosen_layout_which_stays_reachable(
    n: int,
) -> None:
    from benchmarks.adaptive_reach import floor_costs, preview_floor
    from rti_rig.planner import adaptive

    dome, light = _dome(1), (30.0, 50.0)
    preview = _relief_preview(light)
    start_fn = start_functions(preview, light)["preview-floor"]
    start = start_fn(dome, 4, n)
    costs = floor_costs(preview, dome, n, light)
    assert start_fn.costs == [costs]
    assert start_fn.chosen == [(n, preview_floor(costs, DESIGN_DEFAULT_FLOOR))]
    floor = start_fn.chosen[0][1]
    layout = {int(i) for i in select_uniform_leds(dome, n, floor)}
    assert len(set(start)) == 4 and set(start) <= layout
    avail = np.ones(dome.count, dtype=bool)
    avail[start] = False
    comp = adaptive.homogeneous_completion(dome.directions, avail, dome.directions[start], n, floor)
    assert comp is not None
    assert set(start) | {int(i) for i in comp} == layout
    # with its floor the shipped one the start is the shipped start
    if floor == DESIGN_DEFAULT_FLOOR:
        assert sorted(start) == sorted(dome_start(dome, 4, n))


def test_the_preview_floor_start_without_a_preview_scores_a_level_surface() -> None:
    start_fn = start_functions()["preview-floor"]
    start = start_fn(_dome(0), 4, 9)
    assert len(start) == 4 and len(start_fn.chosen) == 1
    # N unknown or not above the start: the shipped start, nothing chosen
    assert start_fn(_dome(0), 4, None) == dome_start(_dome(0), 4, None)
    assert len(start_fn.chosen) == 1
