"""The map of a light plan (rti_rig.app.plan_figure, `rti-rig plan --figure`).

A plan is checked on this map before the rig moves, so the map must put every light where the
frame of docs/conventions.md says it is (azimuth from +x towards +y, distance from the
centre = 90° − elevation) and number the lights in the order they fire.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.app.plan_figure import (
    check_figure_path,
    expected_caption,
    layout_figure,
    polar_coordinates,
    write_layout_figure,
)
from rti_rig.cli import app
from rti_rig.core.errors import RtiRigError
from rti_rig.core.geometry import direction_from_az_el, fibonacci_cap
from rti_rig.core.lp_format import read_lp
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry

REPO = Path(__file__).resolve().parents[2]
DOME = DomeGeometry(fibonacci_cap(40, 5.0, 85.0), tuple(f"led{i:02d}" for i in range(40)))
runner = CliRunner()


def _by_gid(fig, gid: str) -> list:
    ax = fig.axes[0]
    return [a for a in [*ax.collections, *ax.patches, *ax.lines] if a.get_gid() == gid]


def test_polar_coordinates_follow_the_design_frame() -> None:
    t, r = polar_coordinates([direction_from_az_el(30.0, 60.0), direction_from_az_el(250.0, 5.0)])
    np.testing.assert_allclose(np.degrees(t) % 360, [30.0, 250.0], atol=1e-9)
    np.testing.assert_allclose(r, [30.0, 85.0], atol=1e-9)
    t, r = polar_coordinates([0.0, 0.0, 1.0])  # the zenith sits at the centre
    assert r[0] == pytest.approx(0.0, abs=1e-9)


def test_dome_map_places_every_led_and_numbers_the_plan_in_firing_order() -> None:
    order = [7, 2, 31, 18, 25]
    fig = layout_figure(DOME.directions[order], DOME, direction_from_az_el(135.0, 50.0), "t")
    (cands,) = _by_gid(fig, "candidates")
    t, r = polar_coordinates(DOME.directions)
    np.testing.assert_allclose(cands.get_offsets(), np.column_stack([t, r]))
    (chosen,) = _by_gid(fig, "chosen")
    t, r = polar_coordinates(DOME.directions[order])
    np.testing.assert_allclose(chosen.get_offsets(), np.column_stack([t, r]))
    labels = [(a.get_text(), a.get_position()) for a in fig.axes[0].texts]
    assert [text for text, _ in labels] == ["1", "2", "3", "4", "5"]
    np.testing.assert_allclose([pos for _, pos in labels], np.column_stack([t, r]))
    (star,) = _by_gid(fig, "preview")
    np.testing.assert_allclose(star.get_offsets(), [[np.radians(135.0), 40.0]], atol=1e-9)
    assert not _by_gid(fig, "floor") and not _by_gid(fig, "ceiling")  # none given: no ring


def test_dome_map_draws_the_elevation_floor_as_a_full_ring() -> None:
    fig = layout_figure(DOME.directions[[3, 9, 12]], DOME, None, "t", min_elevation_deg=20.0)
    (ring,) = _by_gid(fig, "floor")
    theta, radius = ring.get_data()
    np.testing.assert_allclose(radius, 70.0)  # 90° − the floor's elevation
    assert np.ptp(theta) == pytest.approx(2 * np.pi)
    assert "20°" in ring.get_label()
    assert not _by_gid(fig, "reach")
    # seen from above: azimuth 0° (+x) to the right of the centre, 90° (+y) above it
    fig.canvas.draw()
    centre, east, north = fig.axes[0].transData.transform(
        [(0.0, 0.0), (0.0, 45.0), (np.pi / 2, 45.0)]
    )
    assert east[0] > centre[0] + 10 and abs(east[1] - centre[1]) < 1
    assert north[1] > centre[1] + 10 and abs(north[0] - centre[0]) < 1


@pytest.mark.parametrize(
    ("arm", "azimuths", "radii", "keep"),
    [
        (
            ArmGeometry(5.0, 80.0, 12.0, 0.0, 45.0, -170.0, 170.0),
            (-170.0, 170.0),
            (10.0, 85.0),
            12.0,
        ),
        (ArmGeometry(0.0, 90.0, 0.0, 0.0, 45.0), (-180.0, 180.0), (0.0, 90.0), None),
        (
            ArmGeometry(10.0, 60.0, 5.0, 0.0, 45.0, -180.0, -100.0),
            (-180.0, -100.0),
            (30.0, 80.0),
            5.0,
        ),
    ],
)
def test_arm_map_shades_the_reach_and_hatches_the_keep_out_cone(
    arm: ArmGeometry, azimuths: tuple, radii: tuple, keep: float | None
) -> None:
    chosen = [direction_from_az_el(a, 30.0) for a in (0.0, 90.0, 165.0)]
    fig = layout_figure(chosen, arm)
    (reach,) = _by_gid(fig, "reach")
    verts = reach.get_paths()[0].vertices
    np.testing.assert_allclose([verts[:, 1].min(), verts[:, 1].max()], radii, atol=1e-9)
    az = np.degrees(verts[:, 0])
    np.testing.assert_allclose([az.min(), az.max()], azimuths, atol=1e-9)
    cones = _by_gid(fig, "keep_out")
    if keep is None:
        assert not cones  # no keep-out cone: nothing hatched
    else:
        (cone,) = cones
        np.testing.assert_allclose(cone.get_xy()[:, 1], keep)
    assert not _by_gid(fig, "candidates")


def test_caption_gives_the_plan_and_its_best_starting_layout() -> None:
    text = expected_caption("err", {"uniform ≥0°": 1.4, "uniform ≥10°": 1.3, "optimal": 1.0})
    # four significant digits, kept: a plan's "1.000°" must not read as a rounded "1"
    assert text == "err: optimal 1.000, best starting layout (uniform ≥10°) 1.300"
    assert expected_caption("err", {"uniform ≥0°": 1.4}) == "err: uniform ≥0° 1.400"
    assert expected_caption("err", {}) == ""


def test_map_file_types(tmp_path: Path) -> None:
    with pytest.raises(RtiRigError, match=r"\.png, \.svg, \.pdf"):
        check_figure_path(tmp_path / "map.jpg")
    path = write_layout_figure(tmp_path / "map.svg", layout_figure(DOME.directions[:3], DOME))
    assert path.read_text().lstrip().startswith("<?xml")


@pytest.mark.slow
@pytest.mark.e2e
def test_plan_cli_writes_the_map_and_never_overwrites_unasked(tmp_path: Path) -> None:
    rig = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    base = ["plan", "--rig", str(rig), "--method", "optimal", "--lights", "9"]
    plan, fig = tmp_path / "p.lp", tmp_path / "p.png"
    r = runner.invoke(app, [*base, "--out", str(plan), "--figure", str(fig)])
    assert r.exit_code == 0, r.output
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and plan.is_file()
    assert "Map of the plan" in r.output
    # an existing map is kept unless --force; checked before anything is planned or written
    before = fig.read_bytes()
    r = runner.invoke(app, [*base, "--out", str(tmp_path / "q.lp"), "--figure", str(fig)])
    assert r.exit_code == 2 and "exists" in r.output and fig.read_bytes() == before
    assert not (tmp_path / "q.lp").exists()
    r = runner.invoke(
        app, [*base, "--out", str(tmp_path / "q.lp"), "--figure", str(fig), "--force"]
    )
    assert r.exit_code == 0, r.output
    # a type the map cannot be written as, or the plan file itself: refused up front
    for out, bad, why in (
        (tmp_path / "r.lp", tmp_path / "m.jpg", "give a file ending in"),
        (tmp_path / "r.png", tmp_path / "r.png", "is the --out plan file"),
    ):
        r = runner.invoke(app, [*base, "--out", str(out), "--figure", str(bad)])
        flat = said(r)
        assert r.exit_code == 2 and why in flat, flat
        assert not out.exists()


@pytest.mark.e2e
def test_plan_cli_refuses_a_map_or_plan_it_cannot_write_before_planning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--figure /proc/f.png`` had been refused only after the plan was written ("the plan
    itself was written"), so the same command with a good ``--figure`` then needed ``--force``.
    /proc stands in for a read-only card (the tests may run as root, whom modes do not stop)."""
    import rti_rig.app.usecases.plan as usecase

    rig = REPO / "rig_configs" / "simulated_dome.toml"
    base = ["plan", "--rig", str(rig), "--lights", "9"]
    plan, fig = tmp_path / "p.lp", tmp_path / "p.png"
    real_plan = usecase.plan

    def not_planned(*_: object, **__: object) -> None:
        raise AssertionError("planned before the outputs were checked")

    monkeypatch.setattr(usecase, "plan", not_planned)
    for args, option, bad in (
        (["--out", str(plan), "--figure", "/proc/rti-rig-cannot-write-here.png"], "--figure", 1),
        (["--out", "/proc/rti-rig-cannot-write-here.lp", "--figure", str(fig)], "--out", 0),
    ):
        r = runner.invoke(app, [*base, *args])
        flat = said(r)
        assert r.exit_code == 2, flat
        assert f"{option} {args[2 * bad + 1]}: cannot write there" in flat
        # the folder is named as refusing a new file, not as missing: it had read "(No such
        # file or directory: /proc)", the probe's reason given as the folder's
        assert "(the system refused a new file in /proc: No such file or directory)" in flat
        assert "choose a folder you can write to" in flat and "Traceback" not in flat
        assert not plan.exists() and not fig.exists()
    # an existing plan given with --force is kept when the map cannot be written either
    plan.write_text("kept\n")
    bad_fig = ["--figure", "/proc/rti-rig-cannot-write-here.png", "--force"]
    r = runner.invoke(app, [*base, "--out", str(plan), *bad_fig])
    assert r.exit_code == 2 and plan.read_text() == "kept\n", r.output
    plan.unlink()
    # the same command with a good map needs no --force: nothing had been written
    monkeypatch.setattr(usecase, "plan", real_plan)
    r = runner.invoke(app, [*base, "--out", str(plan), "--figure", str(fig)])
    assert r.exit_code == 0, r.output
    assert len(read_lp(plan)) == 9 and fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.e2e
def test_plan_cli_map_shows_the_lights_of_the_plan_file_in_its_order(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The map drawn is of the plan written: the same lights, in the .lp's (firing) order, and
    the preview light the plan used."""
    import rti_rig.app.plan_figure as plan_figure

    drawn = []
    monkeypatch.setattr(plan_figure, "write_layout_figure", lambda path, fig: drawn.append(fig))
    rig = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    preview = REPO / "tests" / "data" / "neuralrti" / "image11_small.jpg"
    plan = tmp_path / "p.lp"
    args = ["plan", str(preview), "--rig", str(rig), "--lights", "9", "--out", str(plan)]
    r = runner.invoke(
        app,
        [
            *args,
            "--preview-light",
            "120,40",
            "--min-elevation-deg",
            "15",
            "--figure",
            str(tmp_path / "p.png"),
        ],
    )
    assert r.exit_code == 0, r.output
    (fig,) = drawn
    (chosen,) = _by_gid(fig, "chosen")
    t, rad = polar_coordinates([e.direction for e in read_lp(plan)])
    np.testing.assert_allclose(chosen.get_offsets(), np.column_stack([t, rad]), atol=1e-3)
    (ring,) = _by_gid(fig, "floor")  # the plan's floor, with every planned light inside it
    np.testing.assert_allclose(ring.get_data()[1], 75.0)
    assert rad.max() <= 75.0 + 1e-3
    (star,) = _by_gid(fig, "preview")
    np.testing.assert_allclose(star.get_offsets(), [[np.radians(120.0), 50.0]], atol=1e-6)


@pytest.mark.e2e
def test_plan_cli_map_failure_keeps_the_plan_and_its_report(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import rti_rig.app.plan_figure as plan_figure

    def fail(path: Path, fig: object) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(plan_figure, "write_layout_figure", fail)
    rig = REPO / "tests" / "data" / "neuralrti" / "dirs.lp"
    plan = tmp_path / "p.lp"
    args = ["plan", "--rig", str(rig), "--method", "optimal", "--lights", "9", "--out", str(plan)]
    r = runner.invoke(app, [*args, "--figure", str(tmp_path / "p.png")])
    flat = said(r)
    assert r.exit_code == 2 and "disk full" in flat and "the plan itself was written" in flat
    assert "Planned 9 lights" in flat and len(read_lp(plan)) == 9


def test_title_with_dollar_signs_is_drawn_as_text(tmp_path: Path) -> None:
    """A rig file's name goes into the title; matplotlib must not read it as a formula."""
    fig = layout_figure(DOME.directions[:3], DOME, title=r"dome$\frac$.lp")
    write_layout_figure(tmp_path / "m.png", fig)
    assert (tmp_path / "m.png").stat().st_size > 0


def test_a_planned_light_at_the_preview_light_keeps_its_number_visible() -> None:
    """The preview's LED is often planned again: its star is drawn under that light's disc and
    number, and large enough for its points to show around the disc."""
    preview = DOME.directions[7]
    fig = layout_figure(DOME.directions[[2, 7, 31]], DOME, preview, "t")
    (star,) = _by_gid(fig, "preview")
    (chosen,) = _by_gid(fig, "chosen")
    numbers = fig.axes[0].texts
    assert star.get_zorder() < chosen.get_zorder()
    assert all(star.get_zorder() < t.get_zorder() for t in numbers)
    assert star.get_sizes()[0] > 2 * chosen.get_sizes()[0]
