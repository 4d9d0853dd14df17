"""A camera-triggered dome (cceh/rti) through the command line, on the shipped emulated config.

The emulator's record (which LED really lit each exposure) is the truth the session's
``lights.lp`` is held to: a clean run labels every image right; a missed or a double step is
caught at the image it happened, named, the image kept unlabelled, and ``lights.lp`` lists only
correctly labelled images.
"""

from __future__ import annotations

import hashlib
import json
import shlex
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.flash_sync as flash_sync
from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

runner = CliRunner()
SHIPPED = CONFIGS / "emulated_cceh_rti.toml"


def led(index: int) -> str:
    """LED ``index`` (0-based) of the shipped dome's order as every word names it, number and
    direction (``LED 5 (az 112.5°, el 44.7°)``): the words had said the firmware's 1-based
    ``LED 6`` for the LED ``dead_leds = [5]`` names."""
    return rig_geometry(load_rig_config(SHIPPED)).led_said(index)


@pytest.fixture
def rigs(monkeypatch: pytest.MonkeyPatch) -> list:  # type: ignore[type-arg]
    """Every camera-triggered rig the CLI builds (its camera holds the emulator's record)."""
    built: list = []  # type: ignore[type-arg]
    real = flash_sync.build_flash_sync_rig

    def spy(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real(*args, **kwargs)
        built.append(rig)
        return rig

    monkeypatch.setattr(flash_sync, "build_flash_sync_rig", spy)
    return built


def with_fault(tmp_path: Path, at_image: int, kind: str) -> Path:
    text = SHIPPED.read_text(encoding="utf-8")
    text += f'\n[[emulator.sync_faults]]\nat_image = {at_image}\nkind = "{kind}"\n'
    path = tmp_path / "rig.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _run_with_led_6_dead(tmp_path: Path) -> tuple[Path, str]:
    """``rti-rig run`` of the shipped dome with ``[emulator] dead_leds = [5]`` (LED 6 fires,
    gives no light), checked stopped with exit code 2: the session folder and the run's words
    (one line)."""
    config = tmp_path / "rig.toml"
    config.write_text(SHIPPED.read_text(encoding="utf-8") + "\n[emulator]\ndead_leds = [5]\n")
    out = tmp_path / "s"
    result = runner.invoke(app, ["run", str(config), "--out", str(out)])
    assert result.exit_code == 2, result.output
    return out, " ".join(result.output.split())


def truth(rig) -> list[int | None]:  # type: ignore[no-untyped-def]
    """The LED that lit most of each exposure, from the emulator's record."""
    leds: list[int | None] = []
    for _n, t0, t1 in rig.camera.windows:
        seconds = rig.camera.dome.lit_during(t0, t1)
        leds.append(max(seconds, key=lambda k: seconds[k]) if seconds else None)
    return leds


def lp_matches_truth(session: Path, rig) -> int:  # type: ignore[no-untyped-def]
    """Number of lp entries, each asserted to be the light that really lit its image."""
    leds = truth(rig)
    entries = read_lp(session / "lights.lp")
    for e in entries:
        index = int(e.name.removeprefix("image_").removesuffix(".jpg")) - 1
        led = leds[index]
        assert led is not None, f"{e.name} is listed but no LED lit it"
        assert np.allclose(e.direction, rig.geometry.directions[led], atol=1e-6), e.name
    return len(entries)


def test_check_says_what_it_cannot_test_and_shoots_nothing(rigs) -> None:  # type: ignore[no-untyped-def]
    result = runner.invoke(app, ["check", str(SHIPPED)])
    assert result.exit_code == 0, result.output
    assert "camera-triggered (cceh-rti)" in result.output
    assert "cannot light its LEDs" in result.output
    assert "long-press" in result.output
    assert "the proof frame" in " ".join(result.output.split())
    # it ends, as the guide says every check does, with its result
    assert result.output.rstrip().splitlines()[-1].startswith("RESULT: PASS (the camera;")
    assert rigs[0].camera.exposures == 0  # a shot would have stepped the dome
    assert rigs[0].camera.dome.led_index == 0


def test_a_clean_run_labels_every_image_with_the_led_that_lit_it(tmp_path: Path, rigs) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "s"
    result = runner.invoke(app, ["run", str(SHIPPED), "--out", str(out)])
    assert result.exit_code == 0, result.output
    rig = rigs[-1]
    # the firmware's order, one LED per exposure; then the proof frame re-lit the last LED
    assert truth(rig) == [*range(60), 59]
    assert lp_matches_truth(out, rig) == 60
    assert rig.camera.dome.led_index == 61
    text = " ".join(result.output.split())
    assert "end-of-run proof passed" in text and "ran out exactly at image 60" in text
    # the proof frame is kept, never labelled
    proof = out / "unlabelled" / "proof_061"
    assert proof.with_suffix(".tif").is_file() and proof.with_suffix(".json").is_file()
    assert "proof" not in (out / "lights.lp").read_text(encoding="utf-8")
    assert len(list(out.glob("image_*.jpg"))) == 60
    manifest = json.loads((out / "manifest.json").read_text(encoding="utf-8"))
    assert "end-of-run proof passed" in manifest["runner"]["end_check"][0]
    assert not (out / "LABELS_NOT_VERIFIED.txt").exists()  # proven: the session may be used


@pytest.mark.parametrize(
    ("kind", "at_image", "named"),
    [("missed_pulse", 10, "missed step"), ("double_step", 20, "double step")],
)
def test_a_slip_is_caught_at_its_image_named_and_never_labelled(  # type: ignore[no-untyped-def]
    tmp_path: Path, rigs, kind: str, at_image: int, named: str
) -> None:
    out = tmp_path / "s"
    result = runner.invoke(
        app, ["run", str(with_fault(tmp_path, at_image, kind)), "--out", str(out)]
    )
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert f"image {at_image} was not lit by {led(at_image - 1)} of the dome's order" in text
    assert named in text
    rig = rigs[-1]
    assert lp_matches_truth(out, rig) == at_image - 1  # every listed image is right
    # nothing captured is lost: the slipped image is kept, unlabelled, with its verdict
    kept = out / "unlabelled" / f"image_{at_image:03d}"
    assert kept.with_suffix(".tif").is_file() and kept.with_suffix(".json").is_file()
    assert len(list(out.glob("image_*.jpg"))) == at_image - 1
    # labelled and tagged as the session's own linear TIFFs are (it had neither: viewers took
    # it as sRGB-encoded)
    labels = []
    for tif in (kept.with_suffix(".tif"), out / "linear" / "image_001.tif"):
        with tifffile.TiffFile(tif) as f:
            page = f.pages.first
            labels.append((page.description, page.tags.get(34675) and page.tags[34675].value))
    assert labels[0] == labels[1] and labels[0][0].startswith("rti-rig: linear"), labels
    # the lights' state is said as it is: nothing could be sent, nothing confirmed
    low = text.lower()
    assert "no all-off could be sent" in low and "that lights are off is not confirmed" in low
    assert "lights are off" not in low.replace("that lights are off is not", "")
    assert "cannot resume" in text and "--resume" not in text


def test_the_slip_stays_caught_when_the_dome_ran_ahead_at_the_end(tmp_path: Path, rigs) -> None:  # type: ignore[no-untyped-def]
    """A double step on the last image: the firmware has no LED 61, and the next LED would be
    past its order; the image is still judged against the neighbour before it."""
    out = tmp_path / "s"
    result = runner.invoke(
        app, ["run", str(with_fault(tmp_path, 59, "double_step")), "--out", str(out)]
    )
    assert result.exit_code == 2, result.output
    assert "image 59 was not lit" in " ".join(result.output.split())
    assert lp_matches_truth(out, rigs[-1]) == 58


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["--lights", "8"], "--lights 8"),
        (["--auto-exposure"], "--auto-exposure"),
        (["--adaptive"], "--adaptive"),
    ],
)
def test_options_that_would_fire_the_camera_outside_the_sequence_are_refused(  # type: ignore[no-untyped-def]
    tmp_path: Path, rigs, args: list[str], named: str
) -> None:
    out = tmp_path / "s"
    result = runner.invoke(app, ["run", str(SHIPPED), "--out", str(out), *args])
    assert result.exit_code == 2, result.output
    assert named in result.output and "camera-triggered dome" in " ".join(result.output.split())
    assert not out.exists() and rigs == []  # refused before the rig was built


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (["preview", str(SHIPPED), "--out", "OUT"], "preview cannot be used"),
        (["plan", "--rig", str(SHIPPED), "--out", "OUT"], "plan cannot be used"),
        (
            ["run", str(SHIPPED), "--out", "OUT", "--plan", str(CONFIGS / "example_dome_48.lp")],
            "--plan cannot be used",
        ),
    ],
)
def test_preview_and_plans_are_refused(tmp_path: Path, rigs, args: list[str], named: str) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "out"
    result = runner.invoke(app, [str(out) if a == "OUT" else a for a in args])
    assert result.exit_code == 2, result.output
    assert named in " ".join(result.output.split())
    assert not out.exists() and rigs == []


def test_resume_is_refused_because_the_domes_count_went_on(tmp_path: Path) -> None:
    out = tmp_path / "s"
    cfg = with_fault(tmp_path, 5, "missed_pulse")
    assert runner.invoke(app, ["run", str(cfg), "--out", str(out)]).exit_code == 2
    result = runner.invoke(app, ["run", "--resume", str(out)])
    assert result.exit_code == 2
    assert "--resume cannot be used with a camera-triggered dome" in " ".join(result.output.split())


def test_an_exposure_past_the_firmware_timeout_is_refused_at_load(tmp_path: Path) -> None:
    text = SHIPPED.read_text(encoding="utf-8").replace("exposure_s = 0.05", "exposure_s = 5.0")
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text, encoding="utf-8")
    result = runner.invoke(app, ["check", str(cfg)])
    assert result.exit_code == 2
    text = " ".join(result.output.split())
    assert "camera.exposure_s" in text and "off 4 s after the flash" in text


def test_a_serial_link_and_flash_sync_together_are_refused(tmp_path: Path) -> None:
    text = SHIPPED.read_text(encoding="utf-8").replace(
        "[dome.flash_sync]",
        '[dome.serial]\nport = "/dev/null"\nprofile = "rtipy"\n\n[dome.flash_sync]',
    )
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text, encoding="utf-8")
    result = runner.invoke(app, ["check", str(cfg)])
    assert result.exit_code == 2
    assert "has no serial link" in " ".join(result.output.split())


def test_a_double_step_in_the_first_images_disowns_the_session(  # type: ignore[no-untyped-def]
    tmp_path: Path, rigs
) -> None:
    """The documented blind spot: a double step at image 1 shifts every later label, and the
    shifted images explain one another; the whole-set test sees it some images later, and the
    run then says lights.lp is not to be used."""
    out = tmp_path / "s"
    cfg = with_fault(tmp_path, 1, "double_step")
    result = runner.invoke(app, ["run", str(cfg), "--out", str(out)])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert "stepped twice at image" in text
    assert "may be mislabelled: do not use this session" in text
    assert len(read_lp(out / "lights.lp")) <= 20  # seen within the first 21 images
    assert_disowned_session_is_not_used(tmp_path, out)


def with_scene(path: Path, scene: str) -> Path:
    path.write_text(
        path.read_text(encoding="utf-8").replace('name = "relief"', f'name = "{scene}"'),
        encoding="utf-8",
    )
    return path


@pytest.mark.parametrize(("scene", "at_image"), [("coin", 17), ("coin", 45), ("painting", 5)])
def test_a_double_step_the_check_missed_is_caught_by_the_proof_frame(  # type: ignore[no-untyped-def]
    tmp_path: Path, rigs, scene: str, at_image: int
) -> None:
    """On the glossy coin and the low-relief painting the per-image check misses these double
    steps (docs/domes.md); the dome then runs out one image early, so images 59 and 60 and the
    proof frame are all its last LED: the run is disowned, not silently mislabelled."""
    out = tmp_path / "s"
    cfg = with_scene(with_fault(tmp_path, at_image, "double_step"), scene)
    result = runner.invoke(app, ["run", str(cfg), "--out", str(out)])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert "end-of-run proof failed" in text and "stepped twice" in text
    assert "do not use this session" in text and "lights.lp may be mislabelled" in text
    rig = rigs[-1]
    leds = truth(rig)
    assert leds[58:] == [59, 59, 59]  # the fault was real: the dome ran out one image early
    assert leds[at_image] == at_image + 1  # every image after the bounce was one LED ahead
    assert (out / "unlabelled" / "proof_061.tif").is_file()  # nothing captured is lost
    assert not (out / "unlabelled" / "image_061.tif").exists()
    assert_disowned_session_is_not_used(tmp_path, out)


def assert_disowned_session_is_not_used(
    tmp_path: Path, out: Path, why: str = "do not use this session"
) -> None:
    """The disowned session's lights.lp still lists the mislabelled images (nothing is
    rewritten), so fit and export-lp must refuse it, naming the marker that says why."""
    marker = out / "LABELS_NOT_VERIFIED.txt"
    assert marker.is_file() and why in marker.read_text(encoding="utf-8")
    for args in (
        ["fit", str(out), "--out", str(tmp_path / "fitted")],
        ["fit", str(out / "lights.lp"), "--out", str(tmp_path / "fitted2")],
        ["export-lp", str(out), "--out", str(tmp_path / "copy.lp")],
    ):
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (args, result.output)
        text = " ".join(result.output.split())
        assert "LABELS_NOT_VERIFIED.txt" in text and "wrong lights" in text, text
        assert "Traceback" not in result.output
    assert not (tmp_path / "fitted").exists() and not (tmp_path / "copy.lp").exists()


def test_an_order_shorter_than_the_firmware_says_it_is_not_verified(  # type: ignore[no-untyped-def]
    tmp_path: Path, rigs
) -> None:
    """With only the first 52 LEDs listed the dome has not run out after the last image: no
    frame can prove the order held, so none is shot and the run says so. The session folder is
    named 'scan [v2]': the marker's path is said whole (rich had taken '[v2]' for a style tag
    and dropped it)."""
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        SHIPPED.read_text(encoding="utf-8").replace(
            "{ elevation_deg = 10.0, count = 16,", "{ elevation_deg = 10.0, count = 8,"
        ),
        encoding="utf-8",
    )
    out = tmp_path / "scan [v2]"
    result = runner.invoke(app, ["run", str(cfg), "--out", str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "end-of-run proof NOT done" in text and "not verified" in text
    assert f"NOT verified: {out / 'LABELS_NOT_VERIFIED.txt'} says why" in text, text
    assert "lists the lights that fired" not in text  # the labels are not claimed
    assert "labelled with, NOT verified" in text and "LABELS_NOT_VERIFIED.txt" in text
    rig = rigs[-1]
    assert rig.camera.exposures == 52 and rig.camera.dome.led_index == 52  # no extra flash
    assert lp_matches_truth(out, rig) == 52
    assert not (out / "unlabelled").exists()
    marker = out / "LABELS_NOT_VERIFIED.txt"  # not proven, so not used by fit / export-lp
    assert "did not pass it" in marker.read_text(encoding="utf-8")


def test_a_run_stopped_before_its_proof_is_not_used(tmp_path: Path, rigs) -> None:  # type: ignore[no-untyped-def]
    """An unseen double step (coin, image 29), then a missed pulse caught at its own image 41:
    the run stops before the end-of-run proof, with images 29–40 mislabelled in lights.lp. The
    session must be marked from its first image on, so fit and export-lp refuse it."""
    out = tmp_path / "s"
    cfg = with_scene(with_fault(tmp_path, 29, "double_step"), "coin")
    cfg.write_text(
        cfg.read_text(encoding="utf-8")
        + '\n[[emulator.sync_faults]]\nat_image = 41\nkind = "missed_pulse"\n',
        encoding="utf-8",
    )
    result = runner.invoke(app, ["run", str(cfg), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert f"image 41 was not lit by {led(40)}" in " ".join(result.output.split())
    rig = rigs[-1]
    assert truth(rig)[29] == 30  # the fault was real: from the bounce on, one LED ahead
    assert len(read_lp(out / "lights.lp")) == 40  # …and those images are listed in lights.lp
    assert_disowned_session_is_not_used(tmp_path, out, "did not pass it")


def test_resuming_a_finished_session_says_it_is_complete(tmp_path: Path) -> None:
    """A complete session had been told "--resume cannot be used with a camera-triggered dome:
    the dome's own count no longer matches", as if something had interrupted it. Complete and
    intact, its resume is exit 0 with the next step, as any other kind's (it had been exit 2);
    with --reshoot-lost, or an image changed, it is refused: this dome cannot reshoot one."""
    out = tmp_path / "s"
    assert (
        runner.invoke(app, ["run", str(SHIPPED), "--out", str(out), "--no-verdict"]).exit_code == 0
    )
    result = runner.invoke(app, ["run", "--resume", str(out)])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())
    assert "this session is complete: all 60 steps were captured" in text
    assert f"Next: rti-rig fit {out} --out {out}-fit" in text
    assert "cannot be used" not in text and "error" not in text
    # an image renamed is named with its fix (the refusal had said only "nothing to resume")
    (out / "image_020.jpg").rename(out / "photo_x.jpg")
    before = _md5_of_every_file(out)
    result = runner.invoke(app, ["run", "--resume", str(out)])
    assert result.exit_code == 2, result.output
    assert _md5_of_every_file(out) == before
    text = " ".join(result.output.split())
    assert "image_020.jpg as photo_x.jpg is in the folder under another name" in text, text
    (out / "photo_x.jpg").rename(out / "image_020.jpg")
    image = out / "image_003.jpg"
    for extra, change in ((["--reshoot-lost"], False), ([], True), (["--reshoot-lost"], False)):
        lost = image.read_bytes().endswith(b"x")  # the images lost by now
        if change:  # one image changed, one missing since capture
            image.write_bytes(image.read_bytes() + b"x")
            (out / "image_010.jpg").unlink()
        before = _md5_of_every_file(out)
        result = runner.invoke(app, ["run", "--resume", str(out), *extra])
        assert result.exit_code == 2, result.output
        assert _md5_of_every_file(out) == before  # nothing in the folder changed
        text = " ".join(result.output.split())
        assert "this session already completed all 60 steps; nothing to resume" in text
        assert "cannot be used" not in text and "Next:" not in text
        assert "Traceback" not in text
        if extra and not lost:  # --reshoot-lost of an intact session: refused, no image named
            assert "cannot reshoot single images either" in text, text
            assert "long-press the dome's start button" in text and "image_0" not in text
        else:
            # with --reshoot-lost too: it had said "nothing to resume" and not which images
            # were lost, which fit named
            # the images lost are named (the refusal had said only "nothing to resume"),
            # with what this dome can do: never --reshoot-lost, which it refuses
            assert "2 of its images are missing or changed since capture" in text, text
            assert "(image_003, image_010)" in text
            assert "put the originals back from a copy" in text
            assert "cannot continue a session or reshoot single images" in text
            assert "long-press its start button" in text and "NEWDIR" not in text, text
            assert "--reshoot-lost" not in text


def _md5_of_every_file(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (its path inside it) with the md5 of its bytes."""
    return {
        p.relative_to(folder).as_posix(): hashlib.md5(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_a_dead_led_is_named_as_such_and_the_dome_said_to_have_stepped_on(  # type: ignore[no-untyped-def]
    tmp_path: Path, rigs
) -> None:
    """``[emulator] dead_leds`` had been accepted and ignored on the camera-triggered dome: the
    run went through all 60 LEDs with the dead one lit. The firmware fires it (the dome steps);
    it gives no light. The guard then blamed a missed flash pulse and said the dome's count was
    lost, both untrue: the frame shot after the dark image is lit by the next LED, as the order
    says, so the dome stepped on and only the LED stayed dark."""
    out, text = _run_with_led_6_dead(tmp_path)
    assert f"image 6 is dark: {led(5)} did not light (dead LED?); the dome stepped on" in text
    assert f"was lit by {led(6)}, as the order says" in text
    assert f"Repair or replace {led(5)}" in text and "other images are good" in text
    assert "missed step" not in text and "did not reach the dome" not in text
    assert "no longer matches" not in text
    rig = rigs[-1]
    assert truth(rig)[5] == 5  # the firmware did fire LED 6: it is the LED that gave no light
    assert truth(rig)[6] == 6  # …and stepped on: the frame after it is LED 7
    assert lp_matches_truth(out, rig) == 5
    assert (out / "unlabelled" / "image_006.tif").is_file()
    # the frame that told them apart is kept, never labelled
    assert (out / "unlabelled" / "check_007.tif").is_file()
    assert len(list(out.glob("image_*.jpg"))) == 5


def test_a_missed_pulse_is_told_from_a_dead_led_by_the_frame_after_it(  # type: ignore[no-untyped-def]
    tmp_path: Path, rigs
) -> None:
    """A missed pulse gives a dark image too; the frame after it is lit by the LED the dark
    image was due (the dome did not step), which is what the missed-step verdict says."""
    out = tmp_path / "s"
    result = runner.invoke(
        app, ["run", str(with_fault(tmp_path, 21, "missed_pulse")), "--out", str(out)]
    )
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert f"image 21 was not lit by {led(20)}" in text and "missed step" in text, text
    assert "the flash pulse did not reach the dome, which therefore did not step" in text
    assert f"was lit by {led(20)}, the one image 21 was due" in text
    assert "The dome's count no longer matches the session" in text
    assert "dead LED" not in text and "stepped on" not in text
    rig = rigs[-1]
    assert truth(rig)[20] is None and truth(rig)[21] == 20  # dark, then the LED it was due
    assert lp_matches_truth(out, rig) == 20
    assert (out / "unlabelled" / "image_021.tif").is_file()
    assert (out / "unlabelled" / "check_022.tif").is_file()


def test_a_check_frame_the_camera_fails_leaves_both_causes_named(  # type: ignore[no-untyped-def]
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The frame shot after a dark image to tell a dead LED from a missed pulse can fail (a
    camera error): the dark image's verdict is still said, naming both causes."""
    from rti_rig.core.errors import CaptureError

    real = flash_sync.build_flash_sync_rig

    def failing_check_frame(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real(*args, **kwargs)

        def shoot():  # type: ignore[no-untyped-def]
            raise CaptureError("camera", "the USB link dropped")

        rig.capture_check.shoot = shoot
        return rig

    monkeypatch.setattr(flash_sync, "build_flash_sync_rig", failing_check_frame)
    out, text = _run_with_led_6_dead(tmp_path)
    assert f"image 6 was not lit by {led(5)}" in text and f"or {led(5)} is dead" in text, text
    assert "could not be shot (camera: the USB link dropped)" in text
    assert "Traceback" not in text
    assert (out / "unlabelled" / "image_006.tif").is_file()


@pytest.mark.parametrize("refused", ["tiff", "tiff, aside too", "jpeg", "jpeg, aside too"])
def test_a_full_disk_under_unlabelled_still_says_the_slip_and_keeps_the_frame_aside(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, refused: str
) -> None:
    """The slipped image's unlabelled copy refused by the disk: the slip (which image, which
    step) is still said, the stop a slip gets; the frame is kept in a folder of its own in the
    temporary directory, said with the refusal and what to do (a part written under
    unlabelled/ before the refusal is removed, so the move said does not clash), or, if that
    is refused too, said lost with both refusals. The refusal alone had been said ("cannot
    write …/unlabelled/image_004.tif … start a new session"): the double step at image 4 never
    named, and the frame gone with the run."""
    import errno
    import tempfile

    import rti_rig.core.image_files as image_files

    tmp = tmp_path / "tmp"
    old = tmp / "rti-rig-unlabelled-s" / "image_004.tif"  # another session's, named alike
    old.parent.mkdir(parents=True)
    old.write_bytes(b"another session's")
    aside = tmp / "rti-rig-unlabelled-s-2"
    folders = {"unlabelled", aside.name} if refused.endswith("aside too") else {"unlabelled"}
    writers = ["write_srgb_jpeg", "write_untagged_jpeg"] if refused.startswith("jpeg") else []
    for name in writers or ["write_linear_tiff"]:
        real = getattr(image_files, name)

        def full_under_unlabelled(path, *args, _real=real, **kwargs):  # type: ignore[no-untyped-def]
            if Path(path).parent.name not in folders:
                return _real(path, *args, **kwargs)
            raise OSError(errno.ENOSPC, "No space left on device", str(path))

        monkeypatch.setattr(image_files, name, full_under_unlabelled)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    out = tmp_path / "s"
    config = with_fault(tmp_path, 4, "double_step")
    result = runner.invoke(app, ["run", str(config), "--out", str(out)])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert "Traceback" not in text and "please report it" not in text, text
    assert f"image 4 was not lit by {led(3)} of the dome's order — double step" in text, text
    file = "image_004.jpg" if refused.startswith("jpeg") else "image_004.tif"
    refusal = f"cannot write {out / 'unlabelled' / file}: No space left on device (ENOSPC)"
    if refused == "tiff, aside too":
        said = (
            f"Image 4 could not be kept anywhere: {refusal}; nor aside: cannot write "
            f"{aside / 'image_004.tif'}: No space left on device (ENOSPC); the frame was in "
            "memory only and is lost"
        )
        assert not (aside / "image_004.tif").exists()
    elif refused == "jpeg, aside too":  # the TIFF written under unlabelled/ holds the frame
        said = (
            f"Image 4 could not be kept anywhere: {refusal}; nor aside: cannot write "
            f"{aside / 'image_004.jpg'}: No space left on device (ENOSPC); what was written of "
            f"it stays as {out / 'unlabelled' / 'image_004.tif'}, {aside / 'image_004.tif'}"
        )
        assert "is lost" not in text, text
        assert (out / "unlabelled" / "image_004.tif").is_file()
    else:
        said = (
            f"Image 4 is kept, unlabelled, as {aside / 'image_004.tif'} (outside the "
            f"session: {refusal}; free space on that disk, then move the files of {aside} "
            f"into {out / 'unlabelled'}, before the temporary folder is emptied)."
        )
        kept = aside / "image_004"
        assert all(kept.with_suffix(x).is_file() for x in (".tif", ".jpg", ".json"))
        assert (
            tifffile.imread(kept.with_suffix(".tif")).shape
            == tifffile.imread(out / "linear" / "image_001.tif").shape
        )
        assert list((out / "unlabelled").glob("image_004*")) == []  # no part left to clash
    assert said in text, text
    assert old.read_bytes() == b"another session's"  # never overwritten
    assert len(read_lp(out / "lights.lp")) == 3
    manifest = json.loads((out / "manifest.json").read_text(encoding="utf-8"))
    assert manifest["runner"]["finish_reason"] == "error"
    assert said in manifest["runner"]["error"]


def test_refusals_give_the_run_of_the_config_actually_used(tmp_path: Path, rigs) -> None:  # type: ignore[no-untyped-def]
    """The preview refusal (and a finished session's resume) had said "rti-rig run CONFIG
    --out DIR", leaving the user to find which config: it names the one given, as one shell
    word (a folder with a space in its name)."""
    folder = tmp_path / "my rigs"
    folder.mkdir()
    cfg = folder / "cceh dome.toml"
    cfg.write_text(SHIPPED.read_text(encoding="utf-8"), encoding="utf-8")
    run_it = f"rti-rig run {shlex.quote(str(cfg))} --out"
    result = runner.invoke(app, ["preview", str(cfg), "--out", str(tmp_path / "p")])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    # the run into the preview's own --out (nothing was written to it), not a template DIR
    assert (
        "Nothing was fired. Run, with the dome at its first LED (long-press its start button if "
        "it has flashed since it was last rewound), the whole sequence: "
        f"{run_it} {shlex.quote(str(tmp_path / 'p'))}"
    ) in text, text
    assert "CONFIG" not in text and rigs == []
    out = tmp_path / "s"
    assert runner.invoke(app, ["run", str(cfg), "--out", str(out), "--no-verdict"]).exit_code == 0
    # (a plain resume of it is complete, exit 0: refused with --reshoot-lost, naming the run)
    result = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost"])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    again = shlex.quote(str(tmp_path / "s-again"))  # beside the session, not there yet
    assert f"then {run_it} {again})" in text and "CONFIG" not in text, text
