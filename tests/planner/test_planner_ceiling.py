"""An elevation ceiling for plans (``max_elevation_deg``, ``rti-rig plan --max-elevation-deg``).

Lights near the camera axis put mirror highlights on a level glossy object; a ceiling keeps
every planned light at or below it, for every method, on a dome and on an arm, and refuses a
band that is empty before anything is planned.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import az_el_from_direction, direction_from_az_el, fibonacci_cap
from rti_rig.core.lp_format import read_lp
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.make_plan import arm_below, check_elevation_band, make_plan, plan_with_report
from rti_rig.planner.objectives import candidates_for
from rti_rig.planner.uniform import select_uniform_leds
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

REPO = Path(__file__).resolve().parents[2]
DOME = DomeGeometry(fibonacci_cap(60, 5.0, 88.0), tuple(f"led{i:02d}" for i in range(60)))
ARM = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)
SCENE = relief_scene(64, 64, seed=3)
PREVIEW = (np.clip(lambert_radiance(SCENE, direction_from_az_el(30, 50)), 0, 1) * 255).astype(
    np.uint8
)
runner = CliRunner()


def _elevations(sched) -> np.ndarray:
    return np.array([s.elevation_deg for s in sched.steps])


@pytest.mark.slow
@pytest.mark.parametrize("method", ["uniform", "kmeans", "optimal"])
@pytest.mark.parametrize("geometry", [DOME, ARM], ids=["dome", "arm"])
def test_every_light_stays_between_floor_and_ceiling(method: str, geometry) -> None:
    sched = make_plan(
        PREVIEW,
        geometry,
        9,
        method,
        preview_light=(30.0, 50.0),
        min_elevation_deg=10.0,
        max_elevation_deg=55.0,
    )
    el = _elevations(sched)
    assert len(el) == 9
    assert el.min() >= 10.0 - 1e-6 and el.max() <= 55.0 + 1e-6
    if isinstance(geometry, DomeGeometry):
        assert len({s.led for s in sched.steps}) == 9
    else:
        for s in sched.steps:
            assert ARM.unreachable_reason(np.array(s.direction)) is None


def test_without_a_ceiling_the_planner_uses_the_high_lights() -> None:
    """So the ceiling is what keeps them out (the tests above would pass vacuously if the
    plans never went high)."""
    sched = make_plan(None, DOME, 18, "uniform")
    assert _elevations(sched).max() > 70.0


def test_homogeneous_layout_spreads_over_the_band() -> None:
    leds = select_uniform_leds(DOME, 12, 10.0, max_elevation_deg=60.0)
    _, el = az_el_from_direction(DOME.directions[leds])
    _, all_el = az_el_from_direction(DOME.directions)
    band = all_el[(all_el >= 10.0) & (all_el <= 60.0)]
    assert el.max() <= 60.0 + 1e-9 and el.min() >= 10.0 - 1e-9
    assert el.max() > band.max() - 10.0 and el.min() < band.min() + 10.0  # the whole band


def test_candidates_and_arm_are_cut_at_the_ceiling() -> None:
    cands = candidates_for(DOME, 10.0, max_elevation_deg=40.0)
    _, el = az_el_from_direction(cands.directions)
    assert el.max() <= 40.0 + 1e-9 and el.min() >= 10.0 - 1e-9
    arm = candidates_for(ARM, 10.0, max_elevation_deg=40.0)  # the arm's band is cut too
    _, el = az_el_from_direction(arm.directions)
    assert el.max() <= 40.0 + 1e-9 and el.min() >= 10.0 - 1e-9
    with pytest.raises(ScheduleError, match="leaves the arm no band"):
        candidates_for(ARM, 10.0, max_elevation_deg=8.0)
    assert arm_below(ARM, 50.0).max_elevation_deg == 50.0
    assert arm_below(ARM, 85.0) is ARM  # above the arm's own limit: unchanged
    with pytest.raises(ScheduleError, match="at or below the arm's lowest elevation"):
        arm_below(ARM, 5.0)


@pytest.mark.parametrize(
    ("floor", "ceiling", "match"),
    [
        (30.0, 30.0, "above the floor"),
        (30.0, 20.0, "above the floor"),
        (0.0, 95.0, "at most 90"),
        (-5.0, 60.0, r"\[0, 90\)"),
    ],
)
def test_an_empty_or_impossible_band_is_refused(floor: float, ceiling: float, match: str) -> None:
    with pytest.raises(ScheduleError, match=match):
        check_elevation_band(floor, ceiling)
    with pytest.raises(ScheduleError, match=match):
        make_plan(None, DOME, 6, "optimal", min_elevation_deg=floor, max_elevation_deg=ceiling)


def test_too_few_leds_in_the_band_names_the_band_and_how_to_widen_it() -> None:
    with pytest.raises(ScheduleError, match=r"between 10° and 20° elevation; use --lights \d+ or"):
        make_plan(None, DOME, 30, "uniform", min_elevation_deg=10.0, max_elevation_deg=20.0)
    with pytest.raises(ScheduleError, match="widen --min-elevation-deg / --max-elevation-deg") as e:
        make_plan(None, DOME, 6, "optimal", max_elevation_deg=3.0)
    assert "--lights 0" not in str(e.value)  # never advise planning no light


def test_relight_objective_scores_relighting_above_the_ceiling_too(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A user relights from every direction, so the held-out directions the relight objective
    scores reach above the ceiling the planned lights respect."""
    import rti_rig.planner.objectives as objectives

    seen = []
    original = objectives.RelightObjective.__init__

    def spy(self, sample, *args, **kwargs):
        seen.append(sample.held_out)
        original(self, sample, *args, **kwargs)

    monkeypatch.setattr(objectives.RelightObjective, "__init__", spy)
    sched = make_plan(PREVIEW, DOME, 9, "optimal", "relight", (30.0, 50.0), max_elevation_deg=50.0)
    assert _elevations(sched).max() <= 50.0 + 1e-6
    _, held_el = az_el_from_direction(seen[-1])
    assert held_el.max() > 75.0


@pytest.mark.slow
def test_report_shows_the_ceiling_only_where_it_cuts() -> None:
    """An arm that cannot reach 85° is not "kept below 85°" by a ceiling there."""
    _, report = plan_with_report(None, ARM, 6, "optimal", max_elevation_deg=85.0)
    assert report.max_elevation_deg == 90.0
    assert not any("none near the camera axis" in line for line in report.lines())
    _, report = plan_with_report(None, ARM, 6, "optimal", max_elevation_deg=50.0)
    assert any("between 0° and 50° elevation" in line for line in report.lines())


def test_kmeans_under_a_ceiling_says_where_its_lights_land() -> None:
    _, report = plan_with_report(
        PREVIEW, ARM, 9, "kmeans", preview_light=(30.0, 50.0), max_elevation_deg=40.0
    )
    assert any("land on the ceiling's ring" in note for note in report.notes)


def test_report_and_provenance_record_the_ceiling() -> None:
    sched, report = plan_with_report(None, DOME, 6, "optimal", max_elevation_deg=60.0)
    assert report.max_elevation_deg == 60.0
    assert sched.provenance["max_elevation_deg"] == 60.0
    assert any("between 0° and 60° elevation" in line for line in report.lines())
    _, full = plan_with_report(None, DOME, 6, "optimal")
    assert not any("elevation (none near" in line for line in full.lines())


@pytest.mark.e2e
def test_plan_cli_keeps_the_plan_below_the_ceiling_and_draws_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import rti_rig.app.plan_figure as plan_figure

    drawn = []
    monkeypatch.setattr(plan_figure, "write_layout_figure", lambda path, fig: drawn.append(fig))
    rig = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    plan = tmp_path / "p.lp"
    args = ["plan", "--rig", str(rig), "--lights", "12", "--method", "optimal"]
    r = runner.invoke(
        app,
        [
            *args,
            "--max-elevation-deg",
            "60",
            "--out",
            str(plan),
            "--figure",
            str(tmp_path / "m.png"),
        ],
    )
    assert r.exit_code == 0, r.output
    _, el = az_el_from_direction(np.array([e.direction for e in read_lp(plan)]))
    assert len(el) == 12 and el.max() <= 60.0 + 1e-3
    (fig,) = drawn
    (ring,) = [a for a in fig.axes[0].lines if a.get_gid() == "ceiling"]
    np.testing.assert_allclose(ring.get_data()[1], 30.0)  # 90° − 60°
    r = runner.invoke(
        app, [*args, "--min-elevation-deg", "40", "--max-elevation-deg", "30", "--out", str(plan)]
    )
    flat = said(r)
    assert r.exit_code == 2 and "--max-elevation-deg 30" in flat and "above the floor" in flat


def test_ceiling_benchmark_strategies_and_hindsight_floor() -> None:
    """benchmarks.planner_ceiling: every strategy is laid out on the draw's dome, the band
    layouts under the ceiling, the planned ones with their ceiling; the bar's floor is the one
    with the lowest mean."""
    from benchmarks import planner_ceiling as bc

    asked = []

    def plan(g: DomeGeometry, k: int, material: str, ceiling: float) -> np.ndarray:
        asked.append((material, ceiling))
        return select_uniform_leds(g, k, max_elevation_deg=ceiling)

    out = bc.strategies(DOME, 8, plan)
    assert {f"uniform {f:g}" for f in bc.FLOORS} <= set(out)
    assert sorted(asked) == sorted((m, c) for _, m, c in bc.PLANNED)
    for f in bc.BAND_FLOORS:
        _, el = az_el_from_direction(DOME.directions[out[f"band {f:g}"]])
        assert el.max() <= bc.CEILING + 1e-9 and el.min() >= f - 1e-9
    err = {(6, "uniform 0"): [3.0, 3.2], (6, "uniform 10"): [2.0, 2.4], (9, "uniform 0"): [1.0]}
    err[(9, "uniform 10")] = [1.5]
    assert bc.tuned(err, "uniform", (0.0, 10.0)) == "uniform 10"


def test_ceiling_benchmark_bars_are_tuned_per_n_on_the_real_dome_and_once_on_the_simulator() -> (
    None
):
    from benchmarks import planner_ceiling as bc

    err = {}
    for n, best in ((6, 0.0), (9, 20.0)):
        for f in bc.FLOORS:
            err[(n, f"uniform {f:g}")] = [1.0 if f == best else 2.0 + f / 100]
        for f in bc.BAND_FLOORS:
            err[(n, f"band {f:g}")] = [1.5 if f == 10.0 else 3.0]
    per_n = dict(err)
    psnr = {key: [20.0] for key in err}
    names = bc.add_bars(per_n, [6, 9], True, psnr)
    # the relighting shown for the bar is that of the very layouts the normal error chose
    assert (
        psnr[(6, "bar")] is psnr[(6, "uniform 0")] and psnr[(9, "bar")] is psnr[(9, "uniform 20")]
    )
    assert (
        per_n[(6, "bar")] is err[(6, "uniform 0")] and per_n[(9, "bar")] is err[(9, "uniform 20")]
    )
    assert per_n[(9, "band")] is err[(9, "band 10")]
    assert "per N (0/20°)" in names["bar"]
    once = dict(err)
    names = bc.add_bars(once, [6, 9], per_n=False)
    # one floor for every N: floor 0° has the lowest mean over both (1.5 against 1.6 for 20°)
    assert once[(9, "bar")] is err[(9, "uniform 0")] and names["bar"].endswith("floor (0°)")


@pytest.mark.parametrize("geometry", [DOME, ARM], ids=["dome", "arm"])
def test_homogeneous_schedule_under_a_ceiling(geometry) -> None:
    """plan_uniform (what 'rti-rig run --lights N' runs) keeps to the band too."""
    from rti_rig.planner.uniform import plan_uniform

    sched = plan_uniform(geometry, 10, 10.0, max_elevation_deg=45.0)
    el = _elevations(sched)
    assert len(el) == 10 and el.max() <= 45.0 + 1e-6 and el.min() >= 10.0 - 1e-6
    assert sched.provenance["max_elevation_deg"] == 45.0


@pytest.mark.slow
@pytest.mark.e2e
def test_run_cli_runs_the_homogeneous_layout_under_the_ceiling(tmp_path: Path) -> None:
    import json

    cfg = REPO / "rig_configs" / "simulated_dome.toml"
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "8", "--max-elevation-deg", "50"]
    )
    assert r.exit_code == 0, r.output
    _, el = az_el_from_direction(np.array([e.direction for e in read_lp(out / "lights.lp")]))
    assert len(el) == 8 and el.max() <= 50.0 + 1e-3
    manifest = json.loads((out / "manifest.json").read_text())
    assert "max_elevation_deg" in json.dumps(manifest)
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(tmp_path / "t"), "--max-elevation-deg", "0"]
    )
    assert r.exit_code == 2 and "above the floor" in said(r)
    assert not (tmp_path / "t").exists()  # refused before anything was created
