"""The shipped hardware example configs, run through `rti-rig run` up to the device boundary.

The rig is built from the file in rig_configs/ by the composition root, as a user's command
builds it. Only the device libraries are replaced, at their API boundary: python-gphoto2 by a
fake module with a camera body behind it (tests/fake_gphoto2.py), pyserial's port by the dome
firmware emulator on a pseudo-terminal (the configured port name is redirected to the pty;
everything above ``serial.serial_for_url`` is the real stack).
"""

from __future__ import annotations

import hashlib
import json
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from dng_spec_writer import dng, mosaic_from_rgb, srgb8
from fake_gphoto2 import Body, make_module
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import SystemClock
from rti_rig.core.image_files import read_jpeg_rgb, read_linear_tiff

pytestmark = [pytest.mark.pty, pytest.mark.e2e]

DSLR_CONFIG = CONFIGS / "example_dome_48.toml"
WATCH_CONFIG = CONFIGS / "example_dome_48_folder_watch.toml"
H, W = 64, 96
BLACK = (512, 560, 530, 600)  # unequal per CFA site, as some sensors report
WHITE = 16383
BASE = np.array([0.2, 0.5, 0.8])  # the flat patch


def patch_level(led: int | None) -> float:
    """How bright the flat patch is under LED ``led`` (none lit: dark)."""
    return 0.0 if led is None else 0.4 + 0.012 * led


@pytest.fixture
def dome(monkeypatch, request):
    """The shipped config's dome firmware on a pty; its configured port is redirected there."""
    with shipped_dome_on_pty(monkeypatch, getattr(request, "param", DSLR_CONFIG)) as firmware:
        yield firmware


def render_for(firmware):
    """A body's picture: the flat patch, as bright as the LED the emulated firmware lit."""

    def render(body: Body | None = None) -> bytes:
        lit = firmware.lit
        rgb = np.broadcast_to(BASE * patch_level(None if lit is None else lit[0]), (H, W, 3))
        return dng(mosaic_from_rgb(np.array(rgb), "RGGB", BLACK, WHITE), "RGGB", BLACK, WHITE)

    return render


@pytest.fixture
def body(dome, monkeypatch):
    b = Body(render=render_for(dome), clock=SystemClock())  # each shot takes its shutter time
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(b))
    return b


def run(*args: str):
    return CliRunner().invoke(app, ["run", *args])


def journal(out: Path) -> list[dict]:
    return [json.loads(x) for x in (out / "journal.jsonl").read_text().splitlines() if x]


def check_images(out: Path, n: int = 4) -> None:
    """Every step's files are there, in colour, and as bright as its LED made them."""
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed"
    steps = manifest["steps"]
    assert [s["index"] for s in steps] == list(range(n))
    for s in steps:
        expected = BASE * patch_level(s["led"])
        tif = read_linear_tiff(out / s["linear_image"])
        assert tif.shape == (H, W, 3)
        np.testing.assert_allclose(
            tif[8:-8, 8:-8] / 65535, np.broadcast_to(expected, (48, 80, 3)), rtol=1e-3
        )
        jpg = read_jpeg_rgb(out / s["image"]).astype(int)
        assert np.abs(jpg[8:-8, 8:-8] - srgb8(expected)).max() <= 1
        assert s["decode"]["mode"] == "demosaic" and s["decode"]["cfa_pattern"] == "RGGB"
        assert s["decode"]["black_level_per_channel"] == {"R": 512, "G": 560, "B": 600, "G2": 530}
        (raw,) = [k for k in s["originals"]]
        assert raw.startswith("raw/image_") and (out / raw).is_file()
        assert raw in s["sha256"]


def test_dslr_example_downloads_into_the_session_and_keeps_the_raws(body, tmp_path):
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    assert result.exit_code == 0, result.output
    check_images(out)
    entries = journal(out)
    # the camera's own names (RAM target: the same folder every time) are kept in the journal
    names = [next(iter(e["originals"].values())) for e in entries]
    assert names == ["/IMG_0001.CR2", "/IMG_0002.CR2", "/IMG_0003.CR2", "/IMG_0004.CR2"]
    assert body.config["imageformat"] == "RAW" and body.config["capturetarget"] == "Internal RAM"
    assert body.shots == 4 and not body.ram  # nothing left behind in the camera
    assert not any((out / "raw" / ".incoming").iterdir())


def test_camera_switched_off_mid_session_is_named_and_resume_loses_and_repeats_nothing(
    body, tmp_path
):
    out = tmp_path / "s"
    body.off_at_shot = 3
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    assert result.exit_code == 2
    assert "stopped answering" in result.output and "--resume" in result.output
    assert len(journal(out)) == 2
    body.switch_on()
    result = run("--resume", str(out))
    assert result.exit_code == 0, result.output
    check_images(out)
    entries = journal(out)
    assert [e["index"] for e in entries] == [0, 1, 2, 3]  # none repeated, none lost
    assert body.shots == 4
    names = [next(iter(e["originals"].values())) for e in entries]
    assert len(set(names)) == 4


def test_camera_that_names_every_shot_the_same_never_overwrites(body, tmp_path):
    body.naming = "repeat"
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    assert result.exit_code == 0, result.output
    check_images(out)
    names = [next(iter(e["originals"].values())) for e in journal(out)]
    assert names == ["/capt0000.CR2"] * 4
    raws = sorted(p.name for p in (out / "raw").glob("image_*"))
    assert raws == [f"image_00{i}.cr2" for i in range(1, 5)]
    # each kept original is the shot it belongs to (its own brightness), by checksum
    digests = {json.dumps(e["sha256"], sort_keys=True) for e in journal(out)}
    assert len(digests) == 4


@pytest.mark.parametrize("dome", [WATCH_CONFIG], indirect=True)
def test_folder_watch_example_fired_by_the_dome_shutter_line(dome, tmp_path, monkeypatch):
    """A tethering program saves a file into the watched folder each time the dome pulses the
    camera's release line; the session takes each as its light's image."""
    monkeypatch.setenv("HOME", str(tmp_path))
    watched = tmp_path / "Pictures" / "rti-tether"
    watched.mkdir(parents=True)
    render = render_for(dome)
    stop = threading.Event()

    def tethering_program() -> None:
        seen = 0
        while not stop.is_set():
            pulses = [e for e in list(dome.history) if e.what == "shutter"]
            for _ in pulses[seen:]:
                seen += 1
                (watched / f"_DSC{seen:04d}.DNG").write_bytes(render())
            time.sleep(0.01)

    thread = threading.Thread(target=tethering_program, daemon=True)
    thread.start()
    try:
        out = tmp_path / "s"
        result = run(str(WATCH_CONFIG), "--out", str(out), "--lights", "4")
    finally:
        stop.set()
        thread.join(2)
    assert result.exit_code == 0, result.output
    assert sum(e.what == "shutter" for e in dome.history) == 4
    check_images(out)
    names = [next(iter(e["originals"].values())) for e in journal(out)]
    assert names == [f"_DSC{i:04d}.DNG" for i in range(1, 5)]


#: Flat colour patches (linear, fractions of full scale), a 2×3 grid of 32×32 squares.
PATCHES = np.array(
    [
        [(0.2, 0.5, 0.8), (0.9, 0.1, 0.3), (0.05, 0.6, 0.25)],
        [(0.5, 0.5, 0.5), (0.7, 0.35, 0.02), (0.15, 0.15, 0.9)],
    ]
)
SIDE = 32
#: per shot: CFA pattern, black levels per 2×2 site (row by row), Orientation tag, byte order
SHOTS = [
    ("RGGB", (256, 300, 280, 320), 1, False),
    ("BGGR", (600, 512, 540, 580), 6, True),
    ("GRBG", (64, 80, 72, 96), 8, False),
    ("GBRG", (1024, 1000, 1040, 990), 3, True),
]


def patch_image() -> np.ndarray:
    return np.repeat(np.repeat(PATCHES, SIDE, axis=0), SIDE, axis=1)


@pytest.mark.parametrize("dome", [WATCH_CONFIG], indirect=True)
def test_folder_watch_session_of_spec_written_dngs_gives_true_colour(dome, tmp_path, monkeypatch):
    """Must show: DNGs from the tests' own writer (all four CFA patterns, unequal black levels,
    orientation tags, both byte orders) give sRGB JPEGs within 1 code value, linear TIFFs
    within 0.1 %, and the provenance in the manifest."""
    monkeypatch.setenv("HOME", str(tmp_path))
    watched = tmp_path / "Pictures" / "rti-tether"
    watched.mkdir(parents=True)
    files = []
    for pattern, black, orientation, big in SHOTS:
        raw = mosaic_from_rgb(patch_image(), pattern, black, WHITE)
        files.append(dng(raw, pattern, black, WHITE, orientation, big_endian=big))
    stop = threading.Event()

    def tethering_program() -> None:
        seen = 0
        while not stop.is_set():
            pulses = [e for e in list(dome.history) if e.what == "shutter"]
            for _ in pulses[seen:]:
                (watched / f"SHOT{seen + 1}.DNG").write_bytes(files[seen])
                seen += 1
            time.sleep(0.01)

    thread = threading.Thread(target=tethering_program, daemon=True)
    thread.start()
    try:
        out = tmp_path / "s"
        result = run(str(WATCH_CONFIG), "--out", str(out), "--lights", "4")
    finally:
        stop.set()
        thread.join(2)
    assert result.exit_code == 0, result.output
    # the user is told that a rotated camera gave sensor-oriented images
    assert "rotated" in result.output and "sensor" in result.output
    manifest = json.loads((out / "manifest.json").read_text())
    assert any("Orientation tag 6" in n for n in manifest["notices"])
    expected_srgb = srgb8(PATCHES)
    for step, (pattern, black, orientation, _) in zip(manifest["steps"], SHOTS, strict=True):
        tif = read_linear_tiff(out / step["linear_image"]) / 65535
        jpg = read_jpeg_rgb(out / step["image"]).astype(int)
        for r in range(2):
            for c in range(3):
                inner = np.s_[r * SIDE + 8 : (r + 1) * SIDE - 8, c * SIDE + 8 : (c + 1) * SIDE - 8]
                np.testing.assert_allclose(
                    tif[inner], np.broadcast_to(PATCHES[r, c], (16, 16, 3)), rtol=1e-3
                )
                assert np.abs(jpg[inner] - expected_srgb[r, c]).max() <= 1, (pattern, r, c)
        d = step["decode"]
        assert d["mode"] == "demosaic" and d["content"] == "rgb"
        assert d["cfa_pattern"] == pattern
        sites = dict(zip(pattern[:2] + pattern[2:].replace("G", "g"), black, strict=True))
        assert d["black_level_per_channel"]["R"] == sites["R"]
        assert d["black_level_per_channel"]["B"] == sites["B"]
        assert sorted(d["black_level_per_channel"].values()) == sorted(black)
        assert d["white_level"] == WHITE
        assert d["white_balance"].startswith("unity")  # the files carry no as-shot neutral
        assert d["color_space"].startswith("camera RGB")  # ... and no colour matrix
        assert d["orientation"]["orientation_tag"] == orientation
        assert d["orientation"]["applied"] is False
        assert d["orientation"]["camera_rotated"] is (orientation != 1)
        (raw,) = step["originals"]
        assert (out / raw).read_bytes() == files[step["index"]]
        assert d["raw_file"] == raw and d["camera_file"] == f"SHOT{step['index'] + 1}.DNG"
        assert d["source_file"] == raw  # the file decoded, where the session keeps it


def test_dslr_busy_after_every_shot_is_retried_and_the_session_completes(body, tmp_path):
    body.busy_after_shot = 1  # a body still writing the previous file answers "busy" once
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    assert result.exit_code == 0, result.output
    check_images(out)
    assert body.shots == 4 and body.calls.count("capture") == 4 + 3


@pytest.mark.slow
def test_dslr_busy_past_its_leds_max_on_s_is_awaited_with_the_led_off(body, dome, tmp_path):
    """A body writing to a slow card answers busy 4 times after a shot: with the shipped
    config's retries (0.5, 1, 2, 4… s) the fifth try would come 7.7 s after its LED lit,
    past max_on_s = 8 s less the shot. The LED goes off (acknowledged), the camera is awaited
    in the dark, the LED is lit again and the image taken under it. Until 2026-11-29 the
    session stopped there ("raise busy_retries"; raised, the LED then broke max_on_s)."""
    body.busy_after_shot = 4
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "2")
    said = " ".join(result.output.split())
    assert result.exit_code == 0, result.output
    check_images(out, 2)  # each image as bright as its own LED: none taken in the dark
    first, second = journal(out)
    assert first["relit"] == [] and second["relit"], second
    assert all(r["off"] == "acknowledged" for r in second["relit"])
    assert all(r["lit_s"] < 8.0 for r in second["relit"])
    led = second["led"]
    assert "Image 2: the camera is still busy" in said and f"keep LED {led} (lit" in said
    assert "past max_on_s = 8 s: switched off, acknowledged by the dome" in said
    assert "lit again for the shot" in said
    assert "the LED was switched off while the camera was awaited" in said
    assert "[1 of 2 images]" in said
    # the firmware's own log: the step's LED lit, off, lit again, off; never two at once
    log = [(e.what, e.index) for e in dome.history if e.what in ("lit", "off")]
    relit = len(second["relit"])
    assert log[-2 * (relit + 1) :] == [("lit", led), ("off", led)] * (relit + 1)


#: A body in 1/3-stop steps around 1/10 s: it offers no 1/8 s (the shipped example's 0.125 s).
NO_EIGHTH = ["bulb", "30", "1", "1/4", "1/10", "1/13", "1/15", "1/30", "1/60"]


def test_check_fails_a_session_exposure_the_camera_does_not_offer(body, tmp_path):
    """`rti-rig check` had passed the shipped DSLR config on a body without 1/8 s, and the
    session then failed at its first capture, its LED lit, telling the user to "choose one of
    available_exposures_s()"."""
    body.choices["shutterspeed"] = NO_EIGHTH
    result = CliRunner().invoke(app, ["check", str(DSLR_CONFIG)])
    said = " ".join(result.output.split())
    assert result.exit_code != 0 and "RESULT: FAIL" in said, result.output
    assert "camera: dslr connected (no image taken), but FAILED" in said
    assert "exposure 0.125 s is not a shutter speed this camera offers" in said
    assert "0.1 s ('1/10') or 0.25 s ('1/4')" in said and "[camera] exposure_s" in said
    assert body.shots == 0
    body.choices["shutterspeed"] = [*NO_EIGHTH, "1/8"]
    result = CliRunner().invoke(app, ["check", str(DSLR_CONFIG)])
    assert result.exit_code == 0 and "RESULT: PASS" in result.output, result.output


@pytest.mark.slow
def test_ctrl_c_while_a_busy_dslr_is_awaited_in_the_dark_stops_there_and_resumes(
    body, dome, tmp_path, monkeypatch
):
    """Ctrl-C as image 2's LED goes off for a body still busy: the run had waited for the
    camera, lit the LED again and taken the shot before stopping (with a cool-down, up to a
    minute). It stops there now: the LED left off, image 2 not recorded, said, and the resume
    takes it. The signal is sent from inside the process as the LED goes off (no timing)."""
    import os
    import signal

    import rti_rig.cli.session as cli_session

    body.busy_after_shot = 4
    real_said = cli_session._light_off_for_camera

    def ctrl_c_as_the_led_goes_off(event):  # type: ignore[no-untyped-def]
        os.kill(os.getpid(), signal.SIGINT)
        return real_said(event)

    monkeypatch.setattr(cli_session, "_light_off_for_camera", ctrl_c_as_the_led_goes_off)
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "3")
    said = " ".join(result.output.split())
    assert result.exit_code == 130, result.output
    assert [e["index"] for e in journal(out)] == [0] and body.shots == 1
    led = json.loads((out / "manifest.json").read_text())["schedule"]["steps"][1]["led"]
    log = [(e.what, e.index) for e in dome.history if e.what in ("lit", "off")]
    assert log[-2:] == [("lit", led), ("off", led)] and dome.lit is None
    assert "image 2 was not taken: the run was cancelled while its camera was still busy" in said
    assert "acknowledged by the dome: lights are off" in said
    assert f"Continue with: rti-rig run --resume {out}" in said

    monkeypatch.setattr(cli_session, "_light_off_for_camera", real_said)
    result = run("--resume", str(out))
    assert result.exit_code == 0, result.output
    check_images(out, 3)  # each image as bright as its own LED: none taken in the dark


@pytest.mark.parametrize("announced_late", [False, True])
def test_a_picture_taken_behind_a_busy_answer_is_kept_aside_never_as_an_images_file(
    body, tmp_path, announced_late
):
    """A body answers busy once after a shot, yet takes the picture (its release timed out
    while the shot went on, pibooth #466): IMG_0002 is written and announced by event, at once
    or only at the next shot. The session had kept it as a second original of image 2
    (``raw/image_002_2.cr2``, listed in the journal as image 2's camera file), without a word.
    It is now downloaded (nothing captured is lost) and kept in ``strays/``, named as such, in
    the step's ``strays``, never among its originals, and the summary says so."""
    body.busy_after_shot = 1
    body.busy_yet_shot = 1
    body.stray_announced_late = announced_late
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "3")
    said = " ".join(result.output.split())
    assert result.exit_code == 0, result.output
    check_images(out, 3)  # each image's one original, as bright as its own LED
    assert body.stray_files == ["IMG_0002.CR2"] and body.shots == 4
    entries = journal(out)
    names = [next(iter(e["originals"].values())) for e in entries]
    assert names == ["/IMG_0001.CR2", "/IMG_0003.CR2", "/IMG_0004.CR2"]
    assert sorted(p.name for p in (out / "raw").glob("*.cr2")) == [
        f"image_00{i}.cr2" for i in (1, 2, 3)
    ]
    (stray,) = [(e["index"], s) for e in entries for s in e["strays"].items()]
    index, (rel, kept) = stray
    assert index == 1 and rel == "strays/image_002-IMG_0002.CR2"
    assert kept["camera_file"] == "/IMG_0002.CR2"
    data = (out / rel).read_bytes()
    assert hashlib.sha256(data).hexdigest() == kept["sha256"]
    assert "it took while answering busy" in said and "kept aside in strays/" in said
    assert not body.ram  # downloaded and gone from the camera, as every shot


def test_a_raw_and_jpeg_picture_taken_behind_a_busy_answer_is_kept_aside_whole(body, tmp_path):
    """RAW+JPEG, the capture's own path the JPEG (the RAW comes by event): the picture a busy
    answer took (IMG_0002.JPG, then IMG_0002.CR2) is announced before the retried shot's RAW.
    Its JPEG had been kept as image 2's, its RAW as image 2's original and image 2's own RAW
    set aside as the stray: a picture whose exposure the LED may not have covered, recorded as
    the step's. A body naming a shot's files with one stem pairs them by it."""
    text = DSLR_CONFIG.read_text().replace(
        'image_format = "RAW"', 'image_format = "RAW + Large Fine JPEG"\nkeep_jpeg = true'
    )
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    config = tmp_path / "raw_jpeg.toml"
    config.write_text(text)
    body.jpeg_first = True
    body.busy_after_shot = 1
    body.busy_yet_shot = 1
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "3")
    assert result.exit_code == 0, result.output
    assert body.shots == 4
    entries = journal(out)
    stems = [sorted({Path(n).stem for n in e["originals"].values()}) for e in entries]
    assert stems == [["IMG_0001"], ["IMG_0003"], ["IMG_0004"]], entries
    assert [len(e["originals"]) for e in entries] == [2, 2, 2]
    strays = {s: kept["camera_file"] for e in entries for s, kept in e["strays"].items()}
    assert sorted(strays.values()) == ["/IMG_0002.CR2", "/IMG_0002.JPG"], strays
    assert all((out / s).is_file() for s in strays)


def card_config(tmp_path: Path) -> Path:
    """The shipped DSLR example capturing to the camera's card, written into ``tmp_path``."""
    text = DSLR_CONFIG.read_text().replace(
        'capture_target = "Internal RAM"', 'capture_target = "Memory card"'
    )
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    config = tmp_path / "card.toml"
    config.write_text(text)
    return config


def test_the_card_is_listed_for_a_run_only_and_said(body, tmp_path):
    """The card walk had been done at every connect, unsaid: minutes on a full card of a
    Nikon-type body (gphoto2 issue #204), in `check` and `preview` too, which never look for
    a picture taken before a session's first shot. `check` and `preview` no longer list the
    card; `run` says it does before it does."""
    config = card_config(tmp_path)
    result = CliRunner().invoke(app, ["check", str(config)])
    assert result.exit_code == 0 and "RESULT: PASS" in result.output, result.output
    result = CliRunner().invoke(app, ["preview", str(config), "--out", str(tmp_path / "p")])
    assert result.exit_code == 0, result.output
    # the check's test shot (its RAW decoded) and the preview's: neither walks the card
    assert "folder_list_folders" not in body.calls and body.shots == 2, body.calls
    result = run(str(config), "--out", str(tmp_path / "s"), "--lights", "2")
    said = " ".join(result.output.split())
    assert result.exit_code == 0, said
    assert "Listing the camera's card (dslr)" in said, said
    assert "folder_list_folders" in body.calls


@pytest.mark.parametrize("rollover", [False, True], ids=["card-in-use", "card-next-folder"])
def test_a_picture_taken_behind_a_busy_answer_before_the_first_shot_is_found_on_the_card(
    body, tmp_path, rollover
):
    """The body is still writing the owner's last picture as the session starts: its first
    capture answers busy yet takes a picture it never announces. The card folder was first
    listed after the session's first shot, so that picture was taken for one always there and
    stayed on the card unseen. The card is now listed at connect: it is found, kept in
    strays/ and recorded in image 1's strays; the owner's earlier picture is left alone. When
    the owner's picture was file 9999, the body opens the next folder (101CANON) with that
    picture (DCF numbering): a folder not there at connect holds only new files."""
    config = card_config(tmp_path)
    body.card["IMG_0999.CR2"] = b"the owner's earlier picture"
    if rollover:
        body.folder_rollover, body.last_file_number = True, 9999
        body.card = {"IMG_9999.CR2": b"the owner's earlier picture"}
    body.still_writing(1)
    body.busy_yet_shot = 1
    body.stray_never_announced = True
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "2")
    said = " ".join(result.output.split())
    assert result.exit_code == 0, said
    assert body.stray_files == ["IMG_0001.CR2"] and body.shots == 3
    entries = journal(out)
    names = [Path(next(iter(e["originals"].values()))).name for e in entries]
    assert names == ["IMG_0002.CR2", "IMG_0003.CR2"]
    strays = [(e["index"], s) for e in entries for s in e["strays"]]
    assert strays == [(0, "strays/image_001-IMG_0001.CR2")], strays
    assert "it took while answering busy" in said
    if rollover:  # the session's shots were downloaded and deleted from 101CANON
        assert body.card_dir().endswith("101CANON") and not body.card, body.card
        assert list(body.older_folders["/store_00020001/DCIM/100CANON"]) == ["IMG_9999.CR2"]
    else:
        assert sorted(body.card) == ["IMG_0999.CR2"]


def test_a_picture_a_busy_answer_took_and_never_announced_is_found_on_the_card(body, tmp_path):
    """A body answers busy once after a shot yet takes the picture, and never announces it (no
    FILE_ADDED event, ever). Capturing to the card, the picture had stayed there unseen, the
    session saying nothing. The card folder is listed after the busy spell: IMG_0002 is found,
    downloaded into strays/ and recorded in image 2's strays, never as an image; a file on the
    card before the session is left alone; a body never busy costs one listing a session."""
    config = card_config(tmp_path)
    body.card["IMG_0999.CR2"] = b"the owner's earlier picture"
    body.busy_after_shot = 1
    body.busy_yet_shot = 1
    body.stray_never_announced = True
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "3")
    said = " ".join(result.output.split())
    assert result.exit_code == 0, result.output
    check_images(out, 3)
    assert body.stray_files == ["IMG_0002.CR2"] and body.shots == 4
    entries = journal(out)
    names = [Path(next(iter(e["originals"].values()))).name for e in entries]
    assert names == ["IMG_0001.CR2", "IMG_0003.CR2", "IMG_0004.CR2"]
    strays = [(e["index"], s, kept) for e in entries for s, kept in e["strays"].items()]
    assert [(i, s) for i, s, _ in strays] == [(1, "strays/image_002-IMG_0002.CR2")]
    assert strays[0][2]["camera_file"].endswith("/IMG_0002.CR2")
    assert "it took while answering busy" in said
    assert sorted(body.card) == ["IMG_0999.CR2"]  # the stray downloaded and deleted

    # a body that is never busy: its folder listed once, nothing taken as a stray
    body.busy_after_shot = body.busy_yet_shot = 0
    body.still_writing(0)  # done with the last run's last shot (it was busy once after each)
    body.calls.clear()
    result = run(str(config), "--out", str(tmp_path / "t"), "--lights", "3")
    assert result.exit_code == 0, result.output
    assert body.calls.count("folder_list_files") == 1
    assert all(not e["strays"] for e in journal(tmp_path / "t"))
    assert sorted(body.card) == ["IMG_0999.CR2"]


@pytest.mark.parametrize("delete", [True, False])
def test_a_shots_own_jpeg_written_late_is_no_stray_after_a_busy_answer(body, tmp_path, delete):
    """A RAW+JPEG body capturing to its card answers busy once before each shot, taking no
    picture, and writes each shot's JPEG after the RAW's quiet spell (announced only at the
    next shot). The listing after the busy spell found that JPEG on the card and took it for
    a picture "taken while answering busy": images 2-4 each had their own JPEG downloaded into
    strays/ and the run said the body took pictures it never took. A card pairs a shot's files
    by stem: a file of a shot's own stem is no stray."""
    text = DSLR_CONFIG.read_text().replace(
        'capture_target = "Internal RAM"', 'capture_target = "Memory card"'
    )
    text = text.replace(
        'image_format = "RAW"',
        'image_format = "RAW + Large Fine JPEG"'
        + ("" if delete else "\ndelete_from_camera = false"),
    )
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    config = tmp_path / "card.toml"
    config.write_text(text)
    body.busy_after_shot = 1  # busy once after each shot, no picture taken behind it
    body.second_file_quiet_waits = 10**6  # each JPEG announced only at the next shot
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "4")
    assert result.exit_code == 0, result.output
    check_images(out, 4)
    assert body.shots == 4
    assert [s for e in journal(out) for s in e["strays"]] == []
    assert "while answering busy" not in " ".join(result.output.split())
    assert not (out / "strays").exists()


@pytest.mark.parametrize("delete", [True, False])
def test_a_raw_libraw_cannot_read_names_the_file_what_to_do_and_keeps_it(body, tmp_path, delete):
    """A body newer than the bundled LibRaw: its second RAW is a format LibRaw does not know.
    The run had stopped with "…/raw/.incoming/cap0002_IMG_0002.RAF: LibRaw cannot decode this
    file …; is it a complete RAW/DNG download?": no word of a format too new, of what to do,
    or that the camera's copy was already deleted and this is the only one. With
    delete_from_camera = false the shipped config's capture to the camera's RAM keeps no copy
    either: it had been said "the camera's copy kept"."""
    good = body.render
    unknown = b"FUJIFILMCCD-RAW 0201" + bytes(4000)
    body.render = lambda b: unknown if b.shots >= 1 else good(b)
    body.raw_suffix = ".RAF"
    text = DSLR_CONFIG.read_text().replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    if not delete:
        text = text.replace(
            'image_format = "RAW"', 'image_format = "RAW"\ndelete_from_camera = false'
        )
    config = tmp_path / "dslr.toml"
    config.write_text(text)
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "3")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, result.output
    assert "the camera's file IMG_0002.RAF would not decode" in said
    assert "does not read this file's format" in said and "pip install -U rawpy" in said
    copy = "deleted" if delete else 'not kept (a capture to its RAM, capture_target = "Internal'
    assert f"the camera's copy {copy}" in said and "recovered/" in said, said
    assert "copy kept" not in said, said
    kept = out / "raw" / ".incoming" / "cap0002_IMG_0002.RAF"
    assert f"kept at {kept}" in said and kept.read_bytes() == unknown
    assert [e["index"] for e in journal(out)] == [0]


@pytest.mark.parametrize("jpeg_first", [True, False], ids=["jpeg-returned", "raw-returned"])
def test_a_ram_capture_numbered_per_object_keeps_the_last_picture_as_the_shot(
    body, tmp_path, jpeg_first
):
    """RAW+JPEG into the camera's RAM, libgphoto2 naming each object ``captNNNN`` with one
    number per object (capt0002.JPG, capt0003.CR2 …): a picture a busy answer took is
    announced before the retried shot's own files. With the capture returning the JPEG, the
    stray's RAW (capt0003), the first RAW to come, had been kept as image 2 and the stray's
    JPEG as a second JPEG of the step (``raw/image_002_2.jpg``), image 2's own RAW (capt0005)
    set aside as the stray. Objects are numbered as they come and the stray was taken first:
    the shot is the last picture, its JPEG the object next to its RAW."""
    text = DSLR_CONFIG.read_text().replace(
        'image_format = "RAW"', 'image_format = "RAW + Large Fine JPEG"\nkeep_jpeg = true'
    )
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    config = tmp_path / "raw_jpeg.toml"
    config.write_text(text)
    body.naming = "object"
    body.jpeg_first = jpeg_first
    body.busy_after_shot = 1
    body.busy_yet_shot = 1
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "3")
    assert result.exit_code == 0, result.output
    entries = journal(out)
    first, second = ("JPG", "CR2") if jpeg_first else ("CR2", "JPG")
    files = [sorted(Path(n).name for n in e["originals"].values()) for e in entries]
    assert files == [
        sorted([f"capt0000.{first}", f"capt0001.{second}"]),
        sorted([f"capt0004.{first}", f"capt0005.{second}"]),
        sorted([f"capt0006.{first}", f"capt0007.{second}"]),
    ], files
    strays = sorted(Path(k["camera_file"]).name for e in entries for k in e["strays"].values())
    assert strays == sorted([f"capt0002.{first}", f"capt0003.{second}"])
    raws = [k for e in entries for k in e["originals"] if k.endswith(".cr2")]
    assert raws == [f"raw/image_00{i}.cr2" for i in (1, 2, 3)]


@pytest.mark.parametrize("dome", [WATCH_CONFIG], indirect=True)
def test_folder_watch_of_a_raw_libraw_does_not_read_says_so_at_once(dome, tmp_path, monkeypatch):
    """The tethering program saves a whole RAW in a format LibRaw does not read (a body newer
    than it): `rti-rig run` had waited timeout_s (15 s on the example) for the file to change,
    then advised raising stable_polls or poll_interval_s. Now the error names the file, the
    folder it is left in and what to do, at once."""
    monkeypatch.setenv("HOME", str(tmp_path))
    watched = tmp_path / "Pictures" / "rti-tether"
    watched.mkdir(parents=True)
    stop = threading.Event()

    def tethering_program() -> None:
        seen = 0
        while not stop.is_set():
            pulses = [e for e in list(dome.history) if e.what == "shutter"]
            for _ in pulses[seen:]:
                seen += 1
                (watched / f"IMG_{seen:04d}.CR2").write_bytes(
                    b"\x89NEWRAW" + bytes(range(256)) * 64
                )
            time.sleep(0.01)

    thread = threading.Thread(target=tethering_program, daemon=True)
    thread.start()
    try:
        out = tmp_path / "s"
        result = run(str(WATCH_CONFIG), "--out", str(out), "--lights", "4")
    finally:
        stop.set()
        thread.join(2)
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert "IMG_0001.CR2" in said and "does not read this file's format" in said, said
    assert "pip install -U rawpy" in said and "waiting will not help" in said, said
    assert "it is left in" in said and "rti-tether" in said, said
    assert "stable_polls or poll_interval_s" not in said, said
    assert sum(e.what == "shutter" for e in dome.history) == 1
    # the session's copy of the file is dropped with the folders made for it: nothing kept
    assert "may be used again" in said and "--resume" not in said, said
    assert (watched / "IMG_0001.CR2").is_file()


def test_a_card_filled_by_the_kept_copies_says_so_naming_the_key(body, tmp_path):
    """Capturing to the card with delete_from_camera = false, each shot's copy stays on the
    card and fills it: the card-full error had said "free space on it, or set capture_target =
    'Internal RAM'", not that the session's own kept copies were what filled it, nor the key
    that keeps them."""
    text = DSLR_CONFIG.read_text().replace(
        'capture_target = "Internal RAM"',
        'capture_target = "Memory card"\ndelete_from_camera = false',
    )
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    config = tmp_path / "card.toml"
    config.write_text(text)
    body.card_free_shots = 2
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert len(journal(out)) == 2 and len(body.card) == 2  # both kept, on the card and here
    assert "card is full" in said, said
    assert "delete_from_camera = false" in said, said
    assert "2 files this session downloaded are still on it" in said, said
    assert "--resume" in said, said


@pytest.mark.parametrize("target", ["Memory card", "Internal RAM"])
def test_a_picture_taken_behind_a_busy_answer_while_metering_is_said_and_kept_on_the_card(
    body, tmp_path, target
):
    """`run --auto-exposure`: the body answers busy after a test shot yet takes the picture.
    Metering shots are not session images, but that picture, of the object under some light,
    had been downloaded into the metering's private folder and deleted with it (and from the
    card) without a word. Now the run says so, and on a card it is left there."""
    text = DSLR_CONFIG.read_text().replace(
        'capture_target = "Internal RAM"', f'capture_target = "{target}"'
    )
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    config = tmp_path / "meter.toml"
    config.write_text(text)
    body.busy_after_shot = 1
    body.busy_yet_shot = 1
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "3", "--auto-exposure")
    said = " ".join(result.output.split())
    assert result.exit_code == 0, said
    assert body.stray_files == ["IMG_0002.CR2"], body.stray_files
    assert "Metering: the camera delivered 1 picture besides its test shots" in said, said
    assert "IMG_0002.CR2" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    (kept,) = manifest["schedule"]["provenance"]["exposure"]["metering_strays"]
    assert kept["camera_file"].endswith("IMG_0002.CR2")
    if target == "Memory card":
        assert "left on the camera's card" in said, said
        assert "IMG_0002.CR2" in body.card and kept["kept"] == "on the camera's card"
    else:
        assert "not kept" in said, said


@pytest.mark.parametrize("dome", [WATCH_CONFIG], indirect=True)
def test_folder_watch_keeps_the_shot_another_program_moves_out_of_the_folder(
    dome, tmp_path, monkeypatch
):
    """Lightroom's auto import (or a sync tool) moves each file out of the watched folder
    seconds after it comes, while rti-rig decodes it. The file had been decoded where it lay
    and copied at the step's commit, by then gone: `rti-rig run` stopped with "cannot write
    raw/image_001.dng: No such file or directory", as if the disk had failed. The taken file
    is now copied into the session first, and that copy is decoded and kept."""
    import shutil

    import rti_rig.drivers.cameras.folder_watch as folder_watch

    monkeypatch.setenv("HOME", str(tmp_path))
    watched = tmp_path / "Pictures" / "rti-tether"
    watched.mkdir(parents=True)
    library = tmp_path / "library"
    library.mkdir()
    real_decode = folder_watch.decode_raw

    def decoded_while_imported(path, *args, **kwargs):  # type: ignore[no-untyped-def]
        frame = real_decode(path, *args, **kwargs)
        name = Path(path).name
        shutil.move(watched / name, library / name)  # the auto import takes it meanwhile
        return frame

    monkeypatch.setattr(folder_watch, "decode_raw", decoded_while_imported)
    render = render_for(dome)
    stop = threading.Event()

    def tethering_program() -> None:
        seen = 0
        while not stop.is_set():
            pulses = [e for e in list(dome.history) if e.what == "shutter"]
            for _ in pulses[seen:]:
                seen += 1
                (watched / f"_DSC{seen:04d}.DNG").write_bytes(render())
            time.sleep(0.01)

    thread = threading.Thread(target=tethering_program, daemon=True)
    thread.start()
    try:
        out = tmp_path / "s"
        result = run(str(WATCH_CONFIG), "--out", str(out), "--lights", "4")
    finally:
        stop.set()
        thread.join(2)
    assert result.exit_code == 0, result.output
    check_images(out)
    names = [next(iter(e["originals"].values())) for e in journal(out)]
    assert names == [f"_DSC{i:04d}.DNG" for i in range(1, 5)]
    for i in range(1, 5):  # the session's copy is the camera's file, byte for byte
        kept = (out / "raw" / f"image_{i:03d}.dng").read_bytes()
        assert kept == (library / f"_DSC{i:04d}.DNG").read_bytes()
    assert not any((out / "raw" / ".incoming").iterdir())


@pytest.mark.parametrize("dome", [WATCH_CONFIG], indirect=True)
def test_folder_watch_keeps_a_file_set_aside_before_a_pulse_in_strays(dome, tmp_path, monkeypatch):
    """A file that came into the watched folder besides the shot's (a test shot the owner
    took, a duplicate) is set aside at the next pulse, never that light's image. It had been
    named in a notice only, the session holding no copy; now it is kept in strays/ and
    recorded in the step's strays with its checksum, as a DSLR's stray is."""
    import os

    monkeypatch.setenv("HOME", str(tmp_path))
    watched = tmp_path / "Pictures" / "rti-tether"
    watched.mkdir(parents=True)
    render = render_for(dome)
    stop = threading.Event()

    def tethering_program() -> None:
        seen = 0
        while not stop.is_set():
            pulses = [e for e in list(dome.history) if e.what == "shutter"]
            for _ in pulses[seen:]:
                seen += 1
                shot = watched / f"_DSC{seen:04d}.DNG"
                shot.write_bytes(render())
                if seen == 1:  # the owner's test shot, saved after the first shot's file
                    extra = watched / "_DSC9000.DNG"
                    extra.write_bytes(b"II*\0 the owner's test shot")
                    later = shot.stat().st_mtime_ns + 10**9
                    os.utime(extra, ns=(later, later))
            time.sleep(0.01)

    thread = threading.Thread(target=tethering_program, daemon=True)
    thread.start()
    try:
        out = tmp_path / "s"
        result = run(str(WATCH_CONFIG), "--out", str(out), "--lights", "4")
    finally:
        stop.set()
        thread.join(2)
    said = " ".join(result.output.split())
    assert result.exit_code == 0, said
    check_images(out)
    entries = journal(out)
    names = [next(iter(e["originals"].values())) for e in entries]
    assert names == [f"_DSC{i:04d}.DNG" for i in range(1, 5)]
    strays = {s: kept for e in entries for s, kept in e["strays"].items()}
    assert list(strays) == ["strays/image_002-_DSC9000.DNG"], strays
    kept = (out / "strays" / "image_002-_DSC9000.DNG").read_bytes()
    assert kept == b"II*\0 the owner's test shot"
    assert strays["strays/image_002-_DSC9000.DNG"]["camera_file"] == "_DSC9000.DNG"
    assert "_DSC9000.DNG" in said and "strays/" in said, said


def _watch_config_waiting(tmp_path: Path, timeout_s: float) -> Path:
    """The shipped folder-watch example, its wait for a file shortened to ``timeout_s`` (so a
    run stops at a late file in seconds), beside a copy of its .lp."""
    folder = tmp_path / "config"
    folder.mkdir()
    lp = WATCH_CONFIG.with_name("example_dome_48.lp")
    (folder / lp.name).write_bytes(lp.read_bytes())
    cfg = folder / WATCH_CONFIG.name
    text = WATCH_CONFIG.read_text().replace("timeout_s = 15.0", f"timeout_s = {timeout_s}")
    assert f"timeout_s = {timeout_s}" in text
    cfg.write_text(text)
    return cfg


@pytest.mark.parametrize("restarted", [False, True], ids=["same-boot", "after-a-restart"])
def test_folder_watch_resume_sets_aside_a_file_shot_before_it(tmp_path, monkeypatch, restarted):
    """Pulse 2's file is late: the run stops at timeout_s. After `run --resume`, that file
    comes into the folder just before the resumed pulse's own one. It was taken as the
    resumed light's image (the first image after a connect was never checked), a picture
    shot before the stop. The camera clock the first run learned now dates it before the
    resume: it is kept in strays/ and image 2 is the resumed pulse's own file. After a
    restart (the clock file's computer and boot id another), the file, shot the day before,
    was taken unchecked; it is now checked against the computer's wall clock within 10 min."""
    import datetime
    import os

    from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic, write_dng

    monkeypatch.setenv("HOME", str(tmp_path))
    watched = tmp_path / "Pictures" / "rti-tether"
    watched.mkdir(parents=True)
    # the late file's EXIF time is set 30 s back (shot, say, before a long stop): past the
    # check's allowance whatever the tethering thread's lag, with a short wait for its file
    cfg = _watch_config_waiting(tmp_path, 1.5)
    stop = threading.Event()
    mosaic = linear_to_mosaic(np.full((32, 32), 0.3), "RGGB", 256, 4095)

    def save(name: str, stamp: datetime.datetime, mtime_ns: int | None = None) -> None:
        path = watched / name
        write_dng(
            path,
            mosaic,
            black_level=256,
            white_level=4095,
            exposure_s=0.125,
            date_time=stamp.strftime("%Y:%m:%d %H:%M:%S"),
        )
        if mtime_ns is not None:
            os.utime(path, ns=(mtime_ns, mtime_ns))

    with shipped_dome_on_pty(monkeypatch, cfg) as dome:

        def tethering_program() -> None:
            seen, late = 0, None
            while not stop.is_set():
                pulses = [e for e in list(dome.history) if e.what == "shutter"]
                for _ in pulses[seen:]:
                    seen += 1
                    # the camera's clock: UTC wall time, as a camera set to UTC keeps it
                    now = datetime.datetime.now(datetime.UTC).replace(tzinfo=None)
                    if seen == 2:
                        # shot, but its file is on its way past the timeout
                        late = now - datetime.timedelta(seconds=86400 if restarted else 30)
                        continue
                    if seen == 3 and late is not None:  # the late file, just before this one
                        save("_DSC0002.DNG", late, time.time_ns() - 10**9)
                    save(f"_DSC{seen:04d}.DNG", now)
                time.sleep(0.01)

        thread = threading.Thread(target=tethering_program, daemon=True)
        thread.start()
        try:
            out = tmp_path / "s"
            first = run(str(cfg), "--out", str(out), "--lights", "3")
            if restarted:  # as the clock file of the same session written before a restart
                clock_file = out / "raw" / ".folder_watch_clock.json"
                learned = json.loads(clock_file.read_text())
                clock_file.write_text(json.dumps({**learned, "computer": "before-restart"}))
            resumed = run("--resume", str(out))
        finally:
            stop.set()
            thread.join(2)
    assert first.exit_code != 0 and "within 1.5 s" in first.output, first.output
    # a wait this short is within the check's allowance: the config says so, naming both keys
    noted = " ".join(first.output.split())
    assert "timeout_s = 1.5 s is not over twice the allowance" in noted, noted
    assert "shutter_lag_s = 0.5 s" in noted, noted
    said = " ".join(resumed.output.split())
    assert resumed.exit_code == 0, said
    entries = journal(out)
    names = [next(iter(e["originals"].values())) for e in entries]
    assert names == ["_DSC0001.DNG", "_DSC0003.DNG", "_DSC0004.DNG"], names
    strays = {s: kept for e in entries for s, kept in e["strays"].items()}
    assert [kept["camera_file"] for kept in strays.values()] == ["_DSC0002.DNG"], strays
    assert "shot before this run connected" in said, said
    assert ("only to within 10 min" in said) is restarted, said


@pytest.mark.parametrize(
    ("delete", "target"),
    [(True, "Internal RAM"), (False, "Internal RAM"), (False, "Memory card")],
)
def test_a_download_gone_before_its_decode_names_the_camera_s_file_the_folder_and_what_to_do(
    body, tmp_path, monkeypatch, delete, target
):
    """Another program (a sync, backup or antivirus tool) takes the second shot's RAW out of
    the session's download folder as soon as it is written. The run had said "the camera's
    file IMG_0002.CR2 would not decode; it is kept at …/cap0002_IMG_0002.CR2 … RAW file not
    found (moved or deleted before it was read)": a file said kept that was gone, with no word
    of the camera's folder, of what took it or of what to do."""
    import os

    text = DSLR_CONFIG.read_text()
    if not delete:
        text = text.replace(
            'image_format = "RAW"', 'image_format = "RAW"\ndelete_from_camera = false'
        )
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    assert 'capture_target = "Internal RAM"' in text
    text = text.replace('capture_target = "Internal RAM"', f'capture_target = "{target}"')
    config = tmp_path / "dslr.toml"
    config.write_text(text)
    gp = sys.modules["gphoto2"]
    save = gp.CameraFile.save
    written: list[str] = []

    def saved_then_taken(self, target: str) -> None:  # the other program, as the file lands
        save(self, target)
        written.append(target)
        if len(written) == 2:
            os.unlink(target)

    monkeypatch.setattr(gp.CameraFile, "save", saved_then_taken)
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "3")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, result.output
    incoming = out / "raw" / ".incoming"
    assert "RAW file not found" not in said and "would not decode" not in said, said
    assert f"downloaded into {incoming} as cap0002_IMG_0002.CR2" in said, said
    assert "/IMG_0002.CR2 and it was downloaded" in said, said
    assert "moved or deleted by another program" in said, said
    assert f"Keep other programs out of {incoming}" in said, said
    assert "a resumed session shoots this image again" in said, said
    # a capture to the camera's RAM is not kept there once downloaded, deleted or not: it
    # had been said "left on the camera at /IMG_0002.CR2" with delete_from_camera = false
    kept_on_card = not delete and target == "Memory card"
    assert ("so this shot is lost" in said) != kept_on_card, said
    assert ("the camera's copy is left on the camera at" in said) == kept_on_card, said
    assert ("it to its RAM" in said) == (not delete and target == "Internal RAM"), said
    assert [e["index"] for e in journal(out)] == [0]


def test_a_dslr_frame_of_another_size_is_set_aside_with_its_raw_and_both_are_named(
    dome, monkeypatch, tmp_path
):
    """The body's image size changed at the third shot (S-RAW chosen on the camera): the frame
    is refused, and its RAW, the capture itself (a body shooting to its RAM keeps no copy),
    is kept beside the refused frame and named; it had stayed in the hidden raw/.incoming
    under a staging name, unsaid, until a resume moved it to another recovered/ folder."""
    base = render_for(dome)
    made: list[bytes] = []

    def render(b: Body) -> bytes:
        if b.shots < 2:
            return base(b)
        rgb = np.full((2 * H, W, 3), 0.3)
        made.append(dng(mosaic_from_rgb(rgb, "RGGB", BLACK, WHITE), "RGGB", BLACK, WHITE))
        return made[-1]

    monkeypatch.setitem(sys.modules, "gphoto2", make_module(Body(render=render)))
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert "image 3 came back" in said and "Traceback" not in said, said
    (stamp,) = (out / "recovered").iterdir()
    (raw,) = (stamp / "raw").glob("*IMG_0003.CR2")
    assert raw.read_bytes() == made[0]
    assert (stamp / "linear" / "image_003.tif").is_file()
    assert raw.relative_to(out).as_posix() in said, said
    assert not any((out / "raw" / ".incoming").iterdir())


def test_a_first_download_that_fails_leaves_a_folder_said_and_used_as_image_less(body, tmp_path):
    """The first shot's download fails (libgphoto2 -1): nothing is in the session but its own
    empty raw/.incoming. The stop had said "No image was completed, but S holds files of the
    camera" of a folder holding none, and a new run there was refused as "not empty"."""
    body.failures = {"file_get": [-1]}
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert not [p for p in out.rglob("*") if p.is_file() and p.parent.name != out.name]
    assert "holds files of the camera" not in said, said
    assert "holds no image and may be used again" in said, said
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    assert result.exit_code == 0, result.output
    check_images(out)


def test_a_dslr_not_in_manual_mode_is_refused_before_any_led_lights(body, dome, tmp_path):
    """The mode dial is on Av: the body accepts a shutter speed and keeps its own. ISO and the
    format were verified at connect, the shutter only at the first shot: `check` passed the
    camera and `run` lit LED 0 before stopping on it."""
    body.read_only = {"shutterspeed"}
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert "put the camera in manual (M) mode" in said and "shutterspeed" in said, said
    assert not [e for e in dome.history if e.what == "lit"], "an LED was lit"
    assert body.shots == 0 and not out.exists()
    result = CliRunner().invoke(app, ["check", str(DSLR_CONFIG)])
    said = " ".join(result.output.split())
    assert result.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "put the camera in manual (M) mode" in said, said
    assert body.config["shutterspeed"] == "1/60"  # the camera's own, untouched


@pytest.mark.parametrize("own", ["1/60", "bulb"])
def test_check_leaves_a_manual_bodys_shutter_as_it_found_it(body, tmp_path, own):
    """The shutter is tried at connect (another speed, read back) and put back: `check` does
    not change the camera's own setting, a timed speed or bulb."""
    body.config["shutterspeed"] = own
    result = CliRunner().invoke(app, ["check", str(DSLR_CONFIG)])
    assert result.exit_code == 0, result.output
    assert body.config["shutterspeed"] == own
    assert body.calls.count("set_config") >= 3  # format and target, the try, the one put back


def dslr_config(tmp_path: Path, *replace: tuple[str, str]) -> Path:
    """A copy of the shipped DSLR config beside its .lp, with ``replace`` (old, new) applied."""
    text = DSLR_CONFIG.read_text()
    for old, new in replace:
        assert old in text, old
        text = text.replace(old, new)
    cfg = tmp_path / DSLR_CONFIG.name
    cfg.write_text(text)
    (tmp_path / "example_dome_48.lp").write_text((CONFIGS / "example_dome_48.lp").read_text())
    return cfg


#: (the camera's setting name, its choices, the JPEG-only value asked, the RAW choices) as
#: libgphoto2 names them (camlibs/ptp2/config.c): a Canon EOS, a Nikon, a Sony
JPEG_ONLY = [
    ("imageformat", ["Large Fine JPEG", "RAW", "RAW + Large Fine JPEG", "mRAW"], "Large Fine JPEG"),
    ("imagequality", ["JPEG Basic", "JPEG Fine", "NEF (Raw)", "NEF+Fine"], "JPEG Fine"),
    ("imagequality", ["Standard", "Fine", "Extra Fine", "RAW", "RAW+JPEG"], "Extra Fine"),
]


@pytest.mark.parametrize(("setting", "choices", "value"), JPEG_ONLY)
def test_a_jpeg_only_image_format_is_refused_at_connect_before_any_led_lights(
    body, dome, tmp_path, setting, choices, value
):
    """`check` had passed image_format = "Large Fine JPEG", and `run` refused it only at the
    first shot, after LED 0 was lit: the choice is judged by libgphoto2's name at connect."""
    body.config[setting] = choices[0]
    body.choices[setting] = choices
    if setting != "imageformat":
        del body.config["imageformat"], body.choices["imageformat"]
    cfg = dslr_config(
        tmp_path,
        ('image_format = "RAW"', f'image_format = "{value}"\nimage_format_config = "{setting}"'),
    )
    raws = [c for c in choices if "RAW" in c.upper() or "NEF" in c]
    out = tmp_path / "s"
    result = run(str(cfg), "--out", str(out), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert f"image_format = '{value}' in [camera.device] gives JPEG only" in said, said
    assert f"gives a RAW: {raws}" in said, said
    assert "Traceback" not in said
    assert not [e for e in dome.history if e.what == "lit"], "an LED was lit"
    assert body.shots == 0 and not out.exists()
    result = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(result.output.split())
    assert result.exit_code == 1 and "RESULT: FAIL" in said, said
    assert f"image_format = '{value}' in [camera.device] gives JPEG only" in said, said


def test_a_camera_s_own_jpeg_format_is_refused_when_image_format_is_left(body, dome, tmp_path):
    """image_format = "" leaves the camera's own format: a JPEG-only one is refused too."""
    cfg = dslr_config(tmp_path, ('image_format = "RAW"', 'image_format = ""'))
    result = run(str(cfg), "--out", str(tmp_path / "s"), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert "the camera's own imageformat 'Large Fine JPEG'" in said, said
    assert "gives JPEG only" in said and "['RAW', 'RAW + Large Fine JPEG']" in said, said
    assert not [e for e in dome.history if e.what == "lit"], "an LED was lit"
    body.config["imageformat"] = "RAW"  # the owner sets it on the body: the session runs
    result = run(str(cfg), "--out", str(tmp_path / "s"), "--lights", "4")
    assert result.exit_code == 0, result.output
    check_images(tmp_path / "s")


def test_an_image_format_whose_name_cannot_be_judged_is_said_at_check(body, dome, tmp_path):
    """libgphoto2 names a code its table lacks "Unknown value 0007": whether it gives a RAW
    is not known from its name (never guessed). `check`'s test shot tells: a format that gives
    no RAW fails the check, naming the choices known to give RAW (it had passed with a note,
    and the session's first shot refused it), as the first shot still does; one that gives a
    RAW passes with nothing left unknown."""
    unknown = "Unknown value 0007"
    body.choices["imageformat"] = ["Large Fine JPEG", unknown, "RAW"]
    body.format_gives = {unknown: (False, True)}
    cfg = dslr_config(tmp_path, ('image_format = "RAW"', f'image_format = "{unknown}"'))
    result = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(result.output.split())
    assert result.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "camera: dslr connected, but FAILED its test shot" in said, said
    assert "but no RAW file" in said and "RAW+JPEG) value: it offers ['RAW']" in said, said
    assert body.shots == 1
    result = run(str(cfg), "--out", str(tmp_path / "s"), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert "but no RAW file" in said and "RAW+JPEG) value: it offers ['RAW']" in said, said
    assert body.shots == 2
    # the session's shot, taken under its first light, is downloaded and kept, not deleted
    # from the camera undownloaded; the words say where (a resume moves it to recovered/)
    kept = sorted((tmp_path / "s").rglob("cap*"))
    assert len(kept) == 1 and kept[0].suffix.lower() in {".jpg", ".jpeg"}, kept
    assert kept[0].stat().st_size > 0
    assert "The shot is kept at" in said and kept[0].name in said, said
    body.format_gives = {unknown: (True, False)}
    result = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(result.output.split())
    assert result.exit_code == 0 and "RESULT: PASS" in said, said
    assert "its RAW" in said and "does not tell whether it gives a RAW" not in said, said


def test_a_no_raw_shot_that_will_not_download_says_where_it_stays_and_why(body, dome, tmp_path):
    """The session's first shot gives no RAW (a format whose name cannot be judged), and its
    JPEG will not download (libgphoto2 -1): the words say where the shot stays and why its
    download failed (they had said where only), and nothing is deleted from the camera."""
    unknown = "Unknown value 0007"
    body.choices["imageformat"] = ["Large Fine JPEG", unknown, "RAW"]
    body.format_gives = {unknown: (False, True)}
    cfg = dslr_config(tmp_path, ('image_format = "RAW"', f'image_format = "{unknown}"'))
    body.failures["file_get"] = [-1]
    result = run(str(cfg), "--out", str(tmp_path / "s"), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2 and "Traceback" not in said, said
    assert "but no RAW file" in said, said
    assert "Not downloaded: the shot" in said, said
    assert "(the download failed: gphoto2 error -1" in said, said
    assert not sorted((tmp_path / "s").rglob("cap*")), "a file was said not downloaded"


def test_a_download_failed_from_the_camera_s_ram_says_the_shot_is_lost_and_resume_reshoots(
    body, tmp_path
):
    """The second shot's download fails (libgphoto2 -1) while the body shoots to its RAM: the
    message had said only "gphoto2 error -1 … see `gphoto2 --debug` output", not that the
    shot was lost, nor that a resume shoots it again (which it does)."""
    render = body.render

    def fail_second_download(b: Body) -> bytes:
        if b.shots == 1:  # the second shot: its download fails once
            b.failures["file_get"] = [-1]
        return render(b)

    body.render = fail_second_download
    out = tmp_path / "s"
    result = run(str(DSLR_CONFIG), "--out", str(out), "--lights", "4")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert "gphoto2 error -1" in said, said
    assert "taken into the camera's RAM (capture_target = 'Internal RAM'), so it is lost" in said
    # the command itself (a pasteable folder), not the template "SESSION"
    assert f"shoot it again with: rti-rig run --resume {out}" in said, said
    assert "SESSION" not in said, said
    assert [e["index"] for e in journal(out)] == [0]
    result = run("--resume", str(out))
    assert result.exit_code == 0, result.output
    check_images(out)
    assert [e["index"] for e in journal(out)] == [0, 1, 2, 3]
    assert body.shots == 5  # the lost shot taken again, no other


def test_a_monochrome_bodys_raw_is_refused_with_advice_a_gphoto2_rig_can_follow(body, tmp_path):
    """A monochrome body's DNG (LinearRaw, one sample: no colour filter) over gphoto2: the
    decode refuses it, and its advice had been to set ``patterns = ["*.tif"]`` in the rig's
    ``[camera.device]``, a key a gphoto2 camera's config refuses. It names the folder-watch
    camera that reads TIFFs, and the file is kept."""
    from dng_spec_writer import monochrome_dng

    mono = monochrome_dng(np.full((32, 48), 20000, np.uint16))
    body.render = lambda b: mono
    body.raw_suffix = ".DNG"
    text = DSLR_CONFIG.read_text().replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    config = tmp_path / "dslr.toml"
    config.write_text(text)
    out = tmp_path / "s"
    result = run(str(config), "--out", str(out), "--lights", "3")
    said = " ".join(result.output.split())
    assert result.exit_code == 2, said
    assert "Traceback" not in said, said
    assert "the camera's file IMG_0001.DNG would not decode" in said, said
    assert "it is a monochrome sensor's file" in said, said
    assert 'with a folder-watch camera (patterns = ["*.tif"] in its [camera.device])' in said
    kept = out / "raw" / ".incoming" / "cap0001_IMG_0001.DNG"
    assert f"kept at {kept}" in said and kept.read_bytes() == mono, said


def test_a_format_the_body_names_otherwise_says_the_key_to_set_and_its_values(body, tmp_path):
    """The shipped example asks for Canon's "RAW"; a Nikon body calls it "NEF (Raw)". The
    refusal listed the body's values but not what to do with them: the key and its section,
    its value to be one of them, as the camera spells it."""
    body.choices["imageformat"] = ["JPEG Fine", "NEF (Raw)", "NEF+Fine"]
    body.config["imageformat"] = "JPEG Fine"
    result = CliRunner().invoke(app, ["check", str(DSLR_CONFIG)])
    said = " ".join(result.output.split())
    assert result.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "'RAW' is not offered for imageformat" in said, said
    assert "set image_format in [camera.device] to one of them, as the camera spells it" in said
    assert "'NEF (Raw)'" in said and body.shots == 0, said


def test_a_format_the_body_does_not_take_is_not_blamed_on_the_mode_dial(body, tmp_path):
    """The body accepts "RAW" and keeps its JPEG (a format it will not change over USB).
    The refusal said "put the camera in manual (M) mode with auto-ISO off", the advice for an
    exposure setting, nothing of the format."""
    body.read_only = {"imageformat"}
    result = CliRunner().invoke(app, ["check", str(DSLR_CONFIG)])
    said = " ".join(result.output.split())
    assert result.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "imageformat set to 'RAW' but the camera reports 'Large Fine JPEG'" in said, said
    assert "auto-ISO" not in said and "set it on the camera itself" in said, said
    assert 'image_format = "" in [camera.device]' in said and body.shots == 0, said
