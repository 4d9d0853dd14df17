"""The preview shot: its light on each kind of rig, and where `plan` finds a preview's light.

Why: the planner reads the preview's light far better from the rig's record than from the
image, so a light that was recorded must reach it, and a wrong or ambiguous one must not.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO, SMALL_DOME, write_config
from typer.testing import CliRunner

from planner.preview_shot import PREVIEW_AZ_EL_DEG, preview_schedule
from rti_rig.cli import app
from rti_rig.errors import ScheduleError
from rti_rig.geometry import az_el_from_direction, direction_from_az_el
from rti_rig.lp_format import LpEntry, read_lp, write_lp
from rti_rig.preview_source import resolve_preview
from rti_rig.rig_geometry import ArmGeometry, DomeGeometry

runner = CliRunner()
IMAGE = REPO / "tests" / "data" / "neuralrti" / "image11_small.jpg"


def _az_el(direction) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    az, el = az_el_from_direction(np.asarray(direction))
    return round(float(az), 3), round(float(el), 3)


def test_dome_preview_uses_the_nearest_led_and_says_how_far_it_is() -> None:
    az = np.array([0.0, 135.0, 140.0, 135.0])
    el = np.array([50.0, 50.0, 52.0, 85.0])
    dome = DomeGeometry(direction_from_az_el(az, el), ("a", "b", "c", "d"))
    schedule, notes = preview_schedule(dome)
    assert schedule.steps[0].led == 1 and schedule.steps[0].label == "b"
    assert notes == []
    schedule, notes = preview_schedule(dome, (135.0, 80.0))
    assert schedule.steps[0].led == 3
    assert any("nearest, d" in n and "5.0° away" in n for n in notes)
    assert any("85° elevation: outside 30–70°" in n for n in notes)
    assert schedule.provenance["wanted_az_el_deg"] == [135.0, 80.0]


def test_arm_preview_goes_where_asked_or_names_the_limit() -> None:
    arm = ArmGeometry(0.0, 80.0, 15.0, 0.0, 30.0)
    schedule, notes = preview_schedule(arm)
    assert _az_el(schedule.steps[0].direction) == PREVIEW_AZ_EL_DEG
    assert schedule.steps[0].led is None and notes == []
    with pytest.raises(ScheduleError, match="keep-out cone"):
        preview_schedule(arm, (0.0, 88.0))
    with pytest.raises(ScheduleError, match=r"outside 0\.\.90"):
        preview_schedule(arm, (0.0, -5.0))


def test_light_comes_from_an_lp_beside_the_image(tmp_path: Path) -> None:
    img = tmp_path / "shot_07.jpg"
    shutil.copy(IMAGE, img)
    assert resolve_preview(img).light_az_el_deg is None  # nothing records it: estimated
    d = direction_from_az_el(200.0, 45.0)
    write_lp(tmp_path / "acq.lp", [LpEntry("shot_06.jpg", (0, 0, 1)), LpEntry("shot_07.jpg", d)])
    src = resolve_preview(img)
    assert src.image == img
    assert _az_el(direction_from_az_el(*src.light_az_el_deg)) == (200.0, 45.0)
    assert src.light_source == "from acq.lp beside the preview"
    # a second .lp agreeing is fine; one disagreeing is an error naming both
    write_lp(tmp_path / "copy.lp", [LpEntry("shot_07.jpg", d)])
    assert resolve_preview(img).light_az_el_deg is not None
    write_lp(tmp_path / "other.lp", [LpEntry("shot_07.jpg", direction_from_az_el(200.0, 60.0))])
    with pytest.raises(ScheduleError, match=r"acq.lp and other.lp .* 15.0° apart"):
        resolve_preview(img)
    # an unreadable .lp beside the image is not the user's input: skipped
    (tmp_path / "other.lp").write_text("1\nshot_07.jpg 0 0 zero\n")
    assert resolve_preview(img).light_source == "from acq.lp beside the preview"
    # a recorded light below the object plane cannot have lit it: the .lp is named
    (tmp_path / "other.lp").unlink()
    (tmp_path / "copy.lp").unlink()
    write_lp(tmp_path / "acq.lp", [LpEntry("shot_07.jpg", direction_from_az_el(200.0, -10.0))])
    with pytest.raises(ScheduleError, match=r"acq.lp: the light it lists for shot_07.jpg"):
        resolve_preview(img)


def test_session_folders_as_previews(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    one = tmp_path / "one"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(one), "--light", "20,20"])
    assert r.exit_code == 0, r.output
    src = resolve_preview(one)
    assert src.image == one / "linear" / "image_001.tif"
    fired = read_lp(one / "lights.lp")[0].direction
    assert _az_el(direction_from_az_el(*src.light_az_el_deg)) == _az_el(fired)
    # the session's linear TIFF, given directly, finds lights.lp by its number
    linear = resolve_preview(one / "linear" / "image_001.tif")
    assert linear.light_az_el_deg == pytest.approx(src.light_az_el_deg)
    two = tmp_path / "two"
    assert runner.invoke(app, ["run", str(cfg), "--out", str(two), "--lights", "2"]).exit_code == 0
    with pytest.raises(ScheduleError, match="session of 2 images: give the one"):
        resolve_preview(two)
    with pytest.raises(ScheduleError, match="is a folder"):
        resolve_preview(tmp_path)


def test_plan_uses_the_recorded_light_unless_one_is_given(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    shot = tmp_path / "shot"
    assert runner.invoke(app, ["preview", str(cfg), "--out", str(shot)]).exit_code == 0
    base = ["--rig", str(cfg), "--lights", "6"]
    recorded = runner.invoke(app, ["plan", str(shot), *base, "--out", str(tmp_path / "a.lp")])
    assert recorded.exit_code == 0, recorded.output
    assert "(recorded by the session shot)" in recorded.output
    given = ["--preview-light", "135,50", "--out", str(tmp_path / "b.lp")]
    explicit = runner.invoke(app, ["plan", str(shot / "linear" / "image_001.tif"), *base, *given])
    assert explicit.exit_code == 0 and "(given)" in explicit.output
    # the same light and image give the same plan
    assert (tmp_path / "a.lp").read_text() == (tmp_path / "b.lp").read_text()
    other = ["--preview-light", "300,25", "--out", str(tmp_path / "c.lp")]
    r = runner.invoke(app, ["plan", str(shot), *base, *other])
    assert r.exit_code == 0 and "az 300.0°, el 25.0° (given)" in r.output


def test_preview_refuses_before_anything_moves(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "p"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(out), "--light", "north"])
    assert r.exit_code == 2 and "--light 'north'" in r.output
    assert not out.exists()
    (out / "x").mkdir(parents=True)
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(out)])
    assert r.exit_code == 2 and "not empty" in r.output
