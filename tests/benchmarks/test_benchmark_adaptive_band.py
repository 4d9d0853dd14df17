"""`benchmarks.adaptive --min/--max-elevation-deg` measures adaptive within a band.

With a band every strategy compared must keep to it: the adaptive sessions (planned by the CLI's
own ``adaptive_plan``, as ``run --adaptive --max-elevation-deg 45`` plans them), the bar's
homogeneous layouts (``plan --method uniform`` with the band, its floors raised to the band's)
and `optimal` (``plan --method optimal`` with the band). Every layout the benchmark scores is
caught where it is scored, so a strategy that ignored the band fails here.
"""

from __future__ import annotations

import numpy as np
import pytest

import benchmarks.adaptive as bench
import benchmarks.planner_real_data as real_data
import benchmarks.tradeoff as tradeoff


def _elevations(lights: np.ndarray) -> np.ndarray:
    return np.degrees(np.arcsin(np.clip(np.asarray(lights)[:, 2], -1.0, 1.0)))


_RENDERED: dict = {}


def _render_once(scene, settings):  # type: ignore[no-untyped-def]
    """The scene rendered once for both bands (2 s each)."""
    if scene not in _RENDERED:
        _RENDERED[scene] = RENDER(scene, settings)
    return _RENDERED[scene]


RENDER = tradeoff.render_scene_data


@pytest.mark.parametrize(
    ("band", "floors"),
    [((0.0, 45.0), (0.0, 10.0, 20.0, 30.0)), ((20.0, 90.0), (20.0, 30.0))],
)
def test_every_layout_scored_keeps_to_the_band(monkeypatch, band, floors) -> None:
    scored: list[np.ndarray] = []
    planned: list[dict] = []
    normal_error, planned_leds = tradeoff.normal_error, real_data.planned_leds

    def error_spy(normals, images, lights, *args, **kwargs):  # type: ignore[no-untyped-def]
        scored.append(np.asarray(lights))
        return normal_error(normals, images, lights, *args, **kwargs)

    def optimal_spy(*args, **kwargs):  # type: ignore[no-untyped-def]
        planned.append(kwargs)
        return planned_leds(*args, **kwargs)

    monkeypatch.setattr(bench, "_CACHE", {})  # plan afresh, and leave no entry behind
    monkeypatch.setattr(bench, "NS", (9,))
    monkeypatch.setattr(bench, "RELIGHT", False)  # the normals sessions: the band's path
    monkeypatch.setattr(bench, "BAND", band)
    monkeypatch.setattr(tradeoff, "normal_error", error_spy)
    monkeypatch.setattr(real_data, "planned_leds", optimal_spy)
    monkeypatch.setattr(tradeoff, "render_scene_data", _render_once)
    # the relighting scores are not what is tested here (test_benchmark_adaptive_held_out)
    monkeypatch.setattr(bench, "relight_model", lambda *a: None)
    monkeypatch.setattr(bench, "relight_psnr", lambda *a: 0.0)
    monkeypatch.setattr(bench, "written_rti_psnr", lambda *a, **k: ("hsh1", 0.0))
    out, _ = bench.sim(1, scenes=("painting",))
    err = out["painting"]["err"]
    # the bar's floors within the band: 0/10/20/30 under a 45° ceiling, 20/30 above a 20° floor
    assert bench.bar_floors() == floors
    assert {label for _, label in err} == {
        *(f"uniform {f:g}" for f in floors),
        "optimal",
        "adaptive",
        "adaptive relight",
    }
    # `optimal` planned with the band, as `plan --method optimal --min/--max-elevation-deg`
    assert planned == [{"min_elevation_deg": band[0], "max_elevation_deg": band[1]}]
    # every layout scored (the floors, optimal, the adaptive session) has its 9 lights in it
    assert len(scored) == len(floors) + 3
    for lights in scored:
        assert len(lights) == 9
        el = _elevations(lights)
        assert el.min() >= band[0] - 1e-6 and el.max() <= band[1] + 1e-6, el
    # and the band changed something: the 45° ceiling takes the highest lights away (the
    # homogeneous layouts of 9 over the hemisphere reach 70°), the 20° floor the lowest
    top, bottom = (
        max(_elevations(s).max() for s in scored),
        min(_elevations(s).min() for s in scored),
    )
    assert top < 46.0 if band[1] < 90 else bottom > 19.0


def _lambert_dome():  # type: ignore[no-untyped-def]
    """A 120-light dome over every elevation and a 24×24 Lambertian scene's grey images under
    each light: (directions, geometry, normals, images)."""
    from rti_rig.core.geometry import fibonacci_cap
    from rti_rig.core.rig_geometry import DomeGeometry

    dirs = fibonacci_cap(120, 0.0, 90.0)
    dome = DomeGeometry(dirs, tuple(f"c{i:03d}" for i in range(len(dirs))))
    rng = np.random.default_rng(0)
    normals = rng.normal([0.0, 0.0, 3.0], 1.0, size=(24, 24, 3))
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    grey = np.clip(np.einsum("hwk,ck->chw", normals, dirs), 0, None).astype(np.float32)
    return dirs, dome, normals, grey


def test_the_band_s_adaptive_session_is_the_cli_s(monkeypatch) -> None:
    """The session's start is `adaptive_plan`'s (the CLI's): its candidates are the band's, so
    the start and every decision are in it; without a band the same session leaves it."""
    from types import SimpleNamespace

    from rti_rig.app.usecases.adaptive import adaptive_plan

    dirs, dome, _, grey = _lambert_dome()
    free, _, _ = bench.adaptive_run(grey, dirs, dome, 8)
    assert _elevations(dirs[free]).max() > 45.0  # every elevation: the ceiling would bind
    monkeypatch.setattr(bench, "BAND", (0.0, 45.0))
    used, _, _ = bench.adaptive_run(grey, dirs, dome, 8)
    assert len(used) == 8 and _elevations(dirs[used]).max() <= 45.0 + 1e-6
    plan = adaptive_plan(SimpleNamespace(geometry=dome), 8, band=(0.0, 45.0))
    assert used[: len(plan.start)] == [int(plan.leds[c]) for c in plan.start]
    relit, _, _ = bench.adaptive_run(grey, dirs, dome, 8, objective="relight")
    assert len(relit) == 8 and _elevations(dirs[relit]).max() <= 45.0 + 1e-6
    with pytest.raises(ValueError, match="as it ships"):  # no other path is measured so
        bench.adaptive_run(grey, dirs, dome, 60, until=2.0)


def test_a_band_is_written_to_its_own_section_and_checked_as_the_cli_checks_it(
    monkeypatch, capsys
) -> None:
    parse = bench.build_parser().parse_args
    assert bench.band_from(parse([])) is None
    # an explicit full range is no band: the main tables, not a section named "adaptive_band_"
    assert bench.band_from(parse(["--min-elevation-deg", "0", "--max-elevation-deg", "90"])) is None
    assert bench.band_from(parse(["--max-elevation-deg", "45"])) == (0.0, 45.0)
    assert bench.band_from(parse(["--min-elevation-deg", "20"])) == (20.0, 90.0)
    assert bench.band_section(None) == "adaptive_benchmark"  # the main tables, unchanged
    assert bench.band_section((0.0, 45.0)) == "adaptive_band_max45"
    assert bench.band_section((20.0, 90.0)) == "adaptive_band_min20"
    from rti_rig.core.errors import ScheduleError

    with pytest.raises(ScheduleError, match="max-elevation-deg"):
        bench.band_from(parse(["--min-elevation-deg", "50", "--max-elevation-deg", "40"]))
    monkeypatch.setattr(bench, "BAND", None)  # main sets it: restored after the test
    with pytest.raises(SystemExit) as caught:  # the simulator is skipped only within a band
        bench.main(["--sim-draws", "0"])
    assert caught.value.code == 2 and "--sim-draws 0" in capsys.readouterr().err


def test_the_until_error_rows_print_the_upper_estimate_the_stop_compared(monkeypatch) -> None:
    """`until_error_rows` prints the stop's upper estimate as the chooser recorded it (unsolved
    pixels included), not the point × UPPER_FACTOR recomputed, which had printed a smaller
    figure than the stop compared for a session whose unsolved pixels held it back."""
    from types import SimpleNamespace

    from rti_rig.planner.adaptive_until import UPPER_FACTOR

    dirs, dome, normals, grey = _lambert_dome()
    first, _, _ = bench.adaptive_run(grey, dirs, dome, 4, until=1e-9)
    # a patch lit by two of the starting lights only: seen, and never solved
    grey[:, :8, :8] = 0.0
    grey[first[:2], :8, :8] = 0.5
    data = SimpleNamespace(
        candidate_dirs=dirs, normals=normals, candidate_images=np.repeat(grey[..., None], 3, -1)
    )
    monkeypatch.setattr(bench, "TARGETS_DEG", (1e-9,))
    import rti_rig.planner.adaptive as chooser_module

    # until_error_rows sets the estimate's slope on the module: put back after the test
    monkeypatch.setattr(chooser_module, "DISCARD_SLOPE", chooser_module.DISCARD_SLOPE)
    (row,) = bench.until_error_rows({"patch": {"data": (data, grey, dome)}}, 1.0, 0.0)
    cells = [c.strip() for c in row.strip("|").split("|")]
    estimate, upper = float(cells[3].rstrip("°")), float(cells[4].rstrip("°"))
    assert upper > UPPER_FACTOR * estimate + 0.5, row  # the patch's share × 90° is in it
