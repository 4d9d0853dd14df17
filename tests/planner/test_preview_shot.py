"""The preview shot: its light on each kind of rig, and where `plan` finds a preview's light.

Why: the planner reads the preview's light far better from the rig's record than from the
image, so a light that was recorded must reach it, and a wrong or ambiguous one must not.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO, SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.app.preview_source import resolve_preview
from rti_rig.cli import app
from rti_rig.core.errors import ScheduleError
from rti_rig.core.geometry import az_el_from_direction, direction_from_az_el
from rti_rig.core.lp_format import LpEntry, read_lp, write_lp
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry
from rti_rig.planner.preview_shot import PREVIEW_AZ_EL_DEG, preview_schedule

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
    assert any("nearest, LED 3 (" in n and "5.0° away" in n for n in notes)
    assert any("85° elevation: outside 30–70°" in n for n in notes)
    assert schedule.provenance["wanted_az_el_deg"] == [135.0, 80.0]


def test_default_dome_preview_stays_in_the_paper_s_band_when_it_can() -> None:
    """By default a dome's preview LED is the nearest in 45–60° elevation, even when an LED
    outside the band is nearer; asked for a direction, the dome gives its nearest LED."""
    az = np.array([144.0, 157.5, 112.5, 0.0])
    el = np.array([40.0, 55.0, 55.0, 20.0])
    dome = DomeGeometry(direction_from_az_el(az, el), ("low", "right", "left", "far"))
    schedule, notes = preview_schedule(dome)
    assert schedule.steps[0].label in ("right", "left")
    assert any("the nearest in the paper's 45–60° band" in n for n in notes)
    schedule, _ = preview_schedule(dome, PREVIEW_AZ_EL_DEG)
    assert schedule.steps[0].label == "low"
    # a dome with no LED in the band falls back to its nearest LED
    schedule, notes = preview_schedule(DomeGeometry(dome.directions[[0, 3]], ("low", "far")))
    assert schedule.steps[0].label == "low"
    assert any("the nearest, LED 0 (" in n for n in notes)


def test_arm_preview_goes_where_asked_or_names_the_limit() -> None:
    arm = ArmGeometry(0.0, 80.0, 15.0, 0.0, 30.0)
    schedule, notes = preview_schedule(arm)
    assert _az_el(schedule.steps[0].direction) == PREVIEW_AZ_EL_DEG
    assert schedule.steps[0].led is None and notes == []
    with pytest.raises(ScheduleError, match="keep-out cone"):
        preview_schedule(arm, (0.0, 88.0))
    with pytest.raises(ScheduleError, match=r"outside 0\.\.90"):
        preview_schedule(arm, (0.0, -5.0))


def test_a_preview_keeps_to_the_elevation_band_it_is_given() -> None:
    """`plan --max-elevation-deg 45` for a gilded object had been handed a preview already
    shot at 50°: with the band, the default light is chosen in it (a dome's nearest LED in the
    band to the default direction, its elevation clamped), a light asked for outside it is
    refused naming the option, and a dome never fires an LED outside it."""
    az = np.array([135.0, 135.0, 140.0, 300.0])
    el = np.array([50.0, 40.0, 25.0, 45.0])
    dome = DomeGeometry(direction_from_az_el(az, el), ("paper", "low", "lower", "far"))
    assert preview_schedule(dome)[0].steps[0].label == "paper"  # without a band: as before
    schedule, notes = preview_schedule(dome, band=(0.0, 45.0))
    assert schedule.steps[0].label == "low"
    assert schedule.provenance["wanted_az_el_deg"] == [135.0, 45.0]
    assert schedule.provenance["elevation_band_deg"] == [0.0, 45.0]
    assert any("el 45°: the nearest in the band, LED 1 " in n for n in notes), notes
    # the paper's band is preferred where it is part of the band, not where it is its edge
    # ("far", at 45° across the dome, is not taken under the 45° ceiling)
    assert preview_schedule(dome, band=(45.0, 90.0))[0].steps[0].label == "paper"
    # where the band cuts into the paper's, the note names the part searched, not 45–60°
    cut = DomeGeometry(direction_from_az_el([150.0, 135.0], [54.0, 40.0]), ("at 54", "at 40"))
    schedule, notes = preview_schedule(cut, band=(0.0, 55.0))
    assert schedule.steps[0].label == "at 54"
    assert notes == [
        "no LED at az 135°, el 50°: the nearest at 45–55° (the paper's band within yours), "
        "LED 0 (az 150.0°, el 54.0°), is 10.0° away"
    ]
    assert preview_schedule(dome, band=(30.0, 45.0))[0].steps[0].label == "low"
    # a light asked for in the band: the nearest LED in the band, not the nearest overall
    schedule, notes = preview_schedule(dome, (135.0, 46.0), band=(0.0, 46.0))
    assert schedule.steps[0].label == "low"  # "paper" (50°) is nearer, above the band
    assert any("the nearest in the band, LED 1 " in n for n in notes), notes
    with pytest.raises(ScheduleError) as exc:
        preview_schedule(dome, (135.0, 50.0), band=(0.0, 45.0))
    assert "--light 135,50: its elevation 50° is above --max-elevation-deg 45 (the band 0–45°)" in (
        str(exc.value)
    )
    with pytest.raises(ScheduleError, match="below --min-elevation-deg 30"):
        preview_schedule(dome, (135.0, 25.0), band=(30.0, 90.0))
    with pytest.raises(ScheduleError, match="no LED between 60° and 90°"):
        preview_schedule(dome, band=(60.0, 90.0))
    # an arm goes to the default azimuth at the elevation clamped into the band
    arm = ArmGeometry(0.0, 80.0, 15.0, 0.0, 30.0)
    assert _az_el(preview_schedule(arm, band=(0.0, 45.0))[0].steps[0].direction) == (135.0, 45.0)
    assert _az_el(preview_schedule(arm, band=(55.0, 70.0))[0].steps[0].direction) == (135.0, 55.0)


@pytest.mark.slow
@pytest.mark.e2e
def test_preview_and_plan_under_a_ceiling_through_the_front_door(tmp_path: Path) -> None:
    """The gilded object's workflow on the shipped dome: `preview --max-elevation-deg 45` fires
    an LED at or below 45° and says to plan with the same ceiling; `plan` notes a preview shot
    above its ceiling (the default preview, at 55°), and says nothing of one shot within it."""
    cfg = write_config(
        tmp_path,
        (REPO / "rig_configs" / "simulated_dome.toml")
        .read_text()
        .replace("width = 512", "width = 96")
        .replace("height = 512", "height = 96"),
    )
    inside, above = tmp_path / "inside", tmp_path / "above"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(inside), "--max-elevation-deg", "45"])
    assert r.exit_code == 0, r.output
    fired = json.loads((inside / "manifest.json").read_text())["steps"][0]["actual_direction"]
    assert _az_el(fired)[1] <= 45.0 + 1e-6
    assert "--lights 12 --max-elevation-deg 45 --out " in " ".join(r.output.split())
    assert runner.invoke(app, ["preview", str(cfg), "--out", str(above)]).exit_code == 0
    base = ["--rig", str(cfg), "--lights", "8", "--max-elevation-deg", "45"]
    notice = "the preview's light is at 55.0° elevation, above this plan's --max-elevation-deg 45"
    r = runner.invoke(app, ["plan", str(above), *base, "--out", str(tmp_path / "a.lp")])
    assert r.exit_code == 0, r.output
    assert notice in " ".join(r.output.split())
    r = runner.invoke(app, ["plan", str(inside), *base, "--out", str(tmp_path / "b.lp")])
    assert r.exit_code == 0, r.output
    assert "the preview's light is at" not in r.output


def test_light_comes_from_the_rig_lp_listing_the_image_and_no_other_lp(tmp_path: Path) -> None:
    img = tmp_path / "shot_07.jpg"
    shutil.copy(IMAGE, img)
    d = direction_from_az_el(200.0, 45.0)
    dome = tmp_path / "acq.lp"
    write_lp(dome, [LpEntry("shot_06.jpg", (0, 0, 1)), LpEntry("shot_07.jpg", d)])
    # an .lp beside the image is not a record of its light unless the user named it (--rig)
    assert resolve_preview(img).light_az_el_deg is None
    src = resolve_preview(img, (dome, read_lp(dome)))
    assert src.image == img
    assert _az_el(direction_from_az_el(*src.light_az_el_deg)) == (200.0, 45.0)
    assert src.light_source == "recorded by acq.lp"
    # a rig .lp that does not list the preview says nothing about it
    other = tmp_path / "other.lp"
    write_lp(other, [LpEntry("shot_08.jpg", d)])
    assert resolve_preview(img, (other, read_lp(other))).light_az_el_deg is None
    # a light below the object plane cannot have lit it: the .lp is named
    write_lp(dome, [LpEntry("shot_07.jpg", direction_from_az_el(200.0, -10.0))])
    with pytest.raises(ScheduleError, match=r"acq.lp: the light it gives for shot_07.jpg"):
        resolve_preview(img, (dome, read_lp(dome)))


@pytest.mark.e2e
def test_a_plan_beside_the_preview_is_never_read_as_its_light(tmp_path: Path) -> None:
    """A plan's entries are named like a session's images: planning twice from image_001.jpg
    with --out plan.lp beside it must not take a planned light as the preview's."""
    cfg = write_config(tmp_path, SMALL_DOME)
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy(IMAGE, work / "image_001.jpg")
    plan = work / "plan.lp"
    args = ["plan", str(work / "image_001.jpg"), "--rig", str(cfg), "--lights", "6"]
    for _ in range(2):
        r = runner.invoke(app, [*args, "--out", str(plan), "--force"])
        assert r.exit_code == 0, r.output
        assert "(estimated" in r.output and "recorded by" not in r.output
    assert read_lp(plan)[0].name == "image_001.jpg"  # the trap was armed


@pytest.mark.e2e
def test_session_folders_as_previews(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    one = tmp_path / "one"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(one), "--light", "20,20"])
    assert r.exit_code == 0, r.output
    src = resolve_preview(one)
    assert src.image == one / "linear" / "image_001.tif"
    assert src.light_source == "recorded by the session one"
    fired = read_lp(one / "lights.lp")[0].direction
    assert _az_el(direction_from_az_el(*src.light_az_el_deg)) == _az_el(fired)
    with pytest.raises(ScheduleError, match="is a folder"):
        resolve_preview(tmp_path)


@pytest.mark.e2e
def test_images_of_a_session_take_their_step_s_light(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    many = tmp_path / "many"
    assert runner.invoke(app, ["run", str(cfg), "--out", str(many), "--lights", "4"]).exit_code == 0
    with pytest.raises(ScheduleError, match="session of 4 images: give the one"):
        resolve_preview(many)
    lights = read_lp(many / "lights.lp")
    for name, k in (("image_003.jpg", 2), ("linear/image_004.tif", 3)):
        src = resolve_preview(many / name)
        got = _az_el(direction_from_az_el(*src.light_az_el_deg))
        assert got == _az_el(lights[k].direction)
        assert src.light_source == "recorded by the session many"
    # a DSLR session's RAW original in raw/ (as its manifest lists it) takes its step's light
    # too: it had been "estimated" 11° off while the session's JPEG was "recorded"
    manifest = json.loads((many / "manifest.json").read_text())
    manifest["steps"][1]["originals"] = {"raw/image_002.dng": "IMG_0002.DNG"}
    (many / "manifest.json").write_text(json.dumps(manifest))
    (many / "raw").mkdir()
    shutil.copy(many / "linear" / "image_002.tif", many / "raw" / "image_002.dng")
    src = resolve_preview(many / "raw" / "image_002.dng")
    assert _az_el(direction_from_az_el(*src.light_az_el_deg)) == _az_el(lights[1].direction)
    assert src.light_source == "recorded by the session many"
    # a folder called linear that is no session's records nothing
    stray = tmp_path / "stray" / "linear"
    stray.mkdir(parents=True)
    shutil.copy(many / "linear" / "image_004.tif", stray / "image_004.tif")
    write_lp(stray.parent / "lights.lp", read_lp(many / "lights.lp"))
    assert resolve_preview(stray / "image_004.tif").light_az_el_deg is None
    # the session's record and the rig .lp disagreeing is an error naming both
    dome = many / "dome.lp"
    write_lp(dome, [LpEntry("image_003.jpg", direction_from_az_el(10.0, 80.0))])
    with pytest.raises(ScheduleError, match=r"the session .*many and .*dome.lp give the light"):
        resolve_preview(many / "image_003.jpg", (dome, read_lp(dome)))


@pytest.mark.e2e
def test_an_unfinished_session_says_how_to_finish_it(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    shot = tmp_path / "shot"
    assert runner.invoke(app, ["preview", str(cfg), "--out", str(shot)]).exit_code == 0
    manifest = json.loads((shot / "manifest.json").read_text())
    # as a run killed before it finished leaves it (its manifest as the run began)
    for key in ("finished_at", "timing", "lp_file", "notices"):
        manifest.pop(key)
    manifest["runner"] = {"state": "running", "finish_reason": None}
    manifest["steps"] = []
    (shot / "manifest.json").write_text(json.dumps(manifest))
    # its image is journaled, with the light that fired: that is read (it had been said to
    # have "no finished images", then refused as cut off while the journal held the light)
    fired = json.loads((shot / "journal.jsonl").read_text().splitlines()[0])["actual_direction"]
    for target in (shot, shot / "linear" / "image_001.tif"):
        src = resolve_preview(target)
        assert _az_el(direction_from_az_el(*src.light_az_el_deg)) == _az_el(fired)
        assert src.light_source == "recorded by the session shot"
    # killed before its first image was journaled: none is finished
    kept = {p: p.read_bytes() for p in (shot / "journal.jsonl", *(shot / "records").iterdir())}
    for p in kept:
        p.unlink()
    (shot / "journal.jsonl").write_bytes(b"")
    with pytest.raises(ScheduleError, match=r"no finished images.*rti-rig run --resume"):
        resolve_preview(shot)
    for p, data in kept.items():
        p.write_bytes(data)
    # the resume it advises records the light, and plan reads it
    assert runner.invoke(app, ["run", "--resume", str(shot)]).exit_code == 0
    assert resolve_preview(shot).light_az_el_deg is not None
    # ... unless the user gives the light: then the image file is all plan needs
    cfg_args = ["--rig", str(cfg), "--lights", "6", "--out", str(tmp_path / "p.lp")]
    image = str(shot / "linear" / "image_001.tif")
    r = runner.invoke(app, ["plan", image, "--preview-light", "135,50", *cfg_args])
    assert r.exit_code == 0, r.output
    assert "az 135.0°, el 50.0° (given)" in r.output


@pytest.mark.slow
@pytest.mark.e2e
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


@pytest.mark.e2e
def test_preview_refuses_before_anything_moves(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Bad options and an --out that cannot be written are refused before the rig is opened:
    no metering series, no LED, no arm move for a session that could not be kept."""
    import rti_rig.app.compose

    def no_rig(*_: object) -> None:
        raise AssertionError("the rig was opened")

    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "p"
    (out / "x").mkdir(parents=True)
    monkeypatch.setattr(rti_rig.app.compose, "build_rig", no_rig)
    for extra in (["--light", "north"], ["--light", "10,95"], ["--auto-exposure"], []):
        r = runner.invoke(app, ["preview", str(cfg), "--out", str(out), *extra])
        assert r.exit_code == 2, r.output
        assert "Exposure fixed" not in r.output
    assert (
        "the elevation 95° is outside 0..90°"
        in runner.invoke(app, ["preview", str(cfg), "--out", str(out), "--light", "10,95"]).output
    )
    # a folder that is no session is offered no resume (it had been told to resume it)
    assert "not empty" in r.output and "--resume" not in r.output
    # a light outside the band, or a band that is none: refused by name, no traceback
    fresh = tmp_path / "fresh"
    for extra, says in (
        (["--light", "135,50", "--max-elevation-deg", "45"], "above --max-elevation-deg 45"),
        (["--min-elevation-deg", "60", "--max-elevation-deg", "40"], "--max-elevation-deg 40"),
        (["--max-elevation-deg", "95"], "--max-elevation-deg 95"),
    ):
        r = runner.invoke(app, ["preview", str(cfg), "--out", str(fresh), *extra])
        assert r.exit_code == 2 and says in said(r), r.output
        assert "Traceback" not in r.output and not fresh.exists()


class _FakeRig:
    """What the start closes of a rig it opened (:class:`rti_rig.runtime.rig.Rig`'s close
    returns its failures; its ``close_said`` says them)."""

    closed = False

    def close(self) -> list[str]:
        self.closed = True
        return []

    def close_said(self) -> None:
        self.close()


def test_the_rig_is_closed_whatever_interrupts_the_start(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C (or any exception) between opening the rig and the session's start still turns
    the lights off and stops the arm: the rig is closed, and the interruption goes on."""
    import rti_rig.app.compose
    import rti_rig.app.rig_identity
    import rti_rig.app.usecases.session as uc
    from rti_rig.runtime.session import SessionFolder

    rig = _FakeRig()
    monkeypatch.setattr(rti_rig.app.compose, "build_rig", lambda loaded: rig)
    monkeypatch.setattr(rti_rig.app.rig_identity, "rig_identity", lambda loaded: {})

    def interrupted(*_: object) -> None:
        raise KeyboardInterrupt

    from rti_rig.app.config import load_rig_config

    # a real config (its checks before the rig opens read it); the rig itself is the fake
    loaded = load_rig_config(REPO / "rig_configs" / "simulated_dome.toml")
    monkeypatch.setattr(uc, "validate_schedule", interrupted)
    with pytest.raises(KeyboardInterrupt):
        uc.checked_rig(loaded, None)
    assert rig.closed
    rig.closed = False
    monkeypatch.setattr(uc, "validate_schedule", lambda r, s, shot=frozenset(): None)
    monkeypatch.setattr(SessionFolder, "create", interrupted)
    with pytest.raises(KeyboardInterrupt):
        uc._open_new(loaded, [], tmp_path / "new", False, 0.001, uc._ignore)  # type: ignore[arg-type]
    assert rig.closed


def test_an_arm_preview_at_the_edge_of_the_shading_band_is_not_called_outside_it(
    tmp_path: Path,
) -> None:
    """`preview virtual_arm.toml --max-elevation-deg 30` shoots at 30°, which the direction
    reads back as 29.99...°: the note had said "at 30° elevation: outside 30–70°". A preview
    really outside the band (25°) is still noted."""
    cfg = write_config(
        tmp_path,
        (REPO / "rig_configs" / "virtual_arm.toml")
        .read_text()
        .replace("width = 512", "width = 48")
        .replace("height = 512", "height = 48"),
    )
    r = runner.invoke(
        app, ["preview", str(cfg), "--out", str(tmp_path / "p30"), "--max-elevation-deg", "30"]
    )
    assert r.exit_code == 0, r.output
    assert "says little about the relief" not in said(r)
    r = runner.invoke(
        app, ["preview", str(cfg), "--out", str(tmp_path / "p25"), "--max-elevation-deg", "25"]
    )
    assert r.exit_code == 0, r.output
    assert "the preview light is at 25° elevation: outside 30–70°" in said(r)
