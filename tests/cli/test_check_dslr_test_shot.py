"""`rti-rig check` on the shipped DSLR example (its dome firmware emulated on a pty,
python-gphoto2 replaced at its API boundary by tests/fake_gphoto2.py) takes one test shot once
the lights' walk is over and decodes its RAW.

Why: the check took no image, so a body whose RAW the installed LibRaw cannot read (a body
newer than it) passed it, and the session was refused at its first shot, its LED lit, the
schedule begun.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import rawpy
from fake_gphoto2 import Body
from test_dslr_download_disk_full import _config, _raw, _shot_with

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

LIBRAW = f"LibRaw {'.'.join(map(str, rawpy.libraw_version))} (rawpy {rawpy.__version__})"


def _unreadable(body: Body) -> bytes:
    """What a body newer than the installed LibRaw gives it: a file it cannot place."""
    return b"FUTURE-RAW\x00" + bytes(4096)


def test_a_raw_the_installed_libraw_cannot_read_fails_the_check_naming_its_version(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path, "Internal RAM")
    body = Body(render=_unreadable)
    r, said, lit_at_end = _shot_with(monkeypatch, cfg, body, ["check", str(cfg)])
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "Traceback" not in said and lit_at_end is None, said
    assert "lights are off" in said, said
    assert body.shots == 1, said  # one test shot, after the walk
    assert "camera: dslr connected, but FAILED its test shot" in said, said
    assert "dslr (Canon EOS 600D on usb:001,005) gives RAW files the installed" in said, said
    assert f"{LIBRAW} cannot read" in said, said
    assert "pip install -U rawpy" in said and "Shooting JPEG is no way round it" in said, said


@pytest.mark.parametrize("target", ["Internal RAM", "Memory card"])
def test_a_readable_raw_passes_the_check_and_leaves_nothing_on_the_card(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, target: str
) -> None:
    cfg = _config(tmp_path, target)
    body = Body(render=_raw)
    r, said, lit_at_end = _shot_with(monkeypatch, cfg, body, ["check", str(cfg)])
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    assert lit_at_end is None and body.shots == 1, said
    raw = "/IMG_0001.CR2" if target == "Internal RAM" else f"{body.card_dir()}/IMG_0001.CR2"
    assert f"camera: dslr connected (one test shot: its RAW {raw} reads with the" in said, said
    assert LIBRAW in said, said
    assert body.card == {} and body.ram == {}, (body.card, body.ram)
    if target == "Memory card":
        assert body.deleted == ["IMG_0001.CR2"], body.deleted


def test_a_test_shot_kept_on_the_card_is_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path, "Memory card")
    text = cfg.read_text().replace(
        "busy_retries = 6", "busy_retries = 6\ndelete_from_camera = false"
    )
    cfg.write_text(text)
    body = Body(render=_raw)
    r, said, _ = _shot_with(monkeypatch, cfg, body, ["check", str(cfg)])
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    assert "its file stays on the card: delete_from_camera = false" in said, said
    assert list(body.card) == ["IMG_0001.CR2"] and body.deleted == [], body.card


def test_a_run_refused_at_its_first_shot_for_an_unreadable_raw_points_to_the_check(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A session started without the check still meets it at its first shot: the refusal says
    that the check finds it before anything is lit, and keeps the downloaded file."""
    cfg = _config(tmp_path, "Internal RAM")
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch,
        cfg,
        Body(render=_unreadable),
        ["run", str(cfg), "--out", str(out), "--lights", "2"],
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert f"{LIBRAW} does not read this file's format" in said, said
    assert "`rti-rig check` finds a RAW this LibRaw cannot read with a test shot" in said, said
    assert len(list((out / "raw" / ".incoming").glob("cap0001_IMG_0001.CR2"))) == 1


@pytest.mark.parametrize("readable", [True, False], ids=["decoded", "unreadable RAW"])
def test_the_test_shot_puts_the_camera_s_own_shutter_speed_back_even_when_it_fails(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, readable: bool
) -> None:
    """The test shot is taken at the fastest speed offered; the body is left at the speed it
    had, whether the shot's RAW decoded or not (a failed check had left it at 1/250)."""
    cfg = _config(tmp_path, "Internal RAM")
    shot_at: list[str] = []

    def render(body: Body) -> bytes:
        shot_at.append(body.config["shutterspeed"])
        return _raw(body) if readable else _unreadable(body)

    body = Body(render=render)
    r, said, _ = _shot_with(monkeypatch, cfg, body, ["check", str(cfg)])
    assert r.exit_code == (0 if readable else 1) and "Traceback" not in said, said
    assert shot_at == ["1/250"], shot_at  # the fastest speed: the shot did change it
    assert body.config["shutterspeed"] == "1/60", said  # the camera's own, as connect found it


@pytest.mark.parametrize("how", ["set_config fails", "no longer offered"])
def test_a_shutter_speed_a_failed_test_shot_could_not_put_back_is_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, how: str
) -> None:
    """The test shot fails (an unreadable RAW) and putting the camera's own speed back fails
    too: the check had suppressed the second failure, leaving the body at 1/250 unsaid, and a
    speed no longer offered had been said "chosen for [camera] exposure_s" (it is the
    camera's own, as connect found it)."""
    cfg = _config(tmp_path, "Internal RAM")

    def render(body: Body) -> bytes:
        if how == "set_config fails":
            body.failures["set_config"] = [-1]  # the restore's write is refused
        else:  # the mode dial turned to a mode that offers other speeds (the body's own gone)
            body.choices["shutterspeed"] = [c for c in body.choices["shutterspeed"] if c != "1/60"]
        return _unreadable(body)

    body = Body(render=render)
    r, said, _ = _shot_with(monkeypatch, cfg, body, ["check", str(cfg)])
    assert r.exit_code == 1 and "Traceback" not in said, said
    assert body.config["shutterspeed"] == "1/250", said  # the truth: left at the shot's speed
    assert "camera: dslr connected, but FAILED its test shot: " in said, said
    assert f"{LIBRAW} cannot read" in said, said  # the shot's own error, first
    assert (
        "; note: putting the camera's own shutter speed '1/60' back after the test shot "
        "failed (" in said
    ), said
    assert (
        "it was last read back at '1/250' (the test shot's): check and set it on the camera" in said
    ), said
    if how == "no longer offered":
        assert "the camera's own shutter speed '1/60' (as connect found it, put back" in said
        assert "chosen for [camera] exposure_s" not in said, said


def test_an_image_format_a_failed_test_shot_never_reached_is_said_unchecked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """image_format left as the camera has it, on a body with no 'imageformat' setting:
    connect cannot judge it, and a test shot that fails before any file comes (the capture
    refused) leaves it unknown. The note was said only beside an exposure the camera does not
    offer, never beside a failed shot, where it is as true."""
    cfg = _config(tmp_path, "Internal RAM")
    cfg.write_text(cfg.read_text().replace('image_format = "RAW"', 'image_format = ""'))
    body = Body(render=_raw)
    del body.config["imageformat"], body.choices["imageformat"]
    body.failures["capture"] = [-1]
    r, said, _ = _shot_with(monkeypatch, cfg, body, ["check", str(cfg)])
    assert r.exit_code == 1 and "Traceback" not in said, said
    assert "camera: dslr connected, but FAILED its test shot: " in said, said
    assert "; note: image format not checked: the camera has no setting 'imageformat'" in said
    assert body.shots == 0, said
