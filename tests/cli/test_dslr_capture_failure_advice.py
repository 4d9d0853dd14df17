"""A tethered DSLR whose capture fails for good, through `rti-rig run` on the shipped DSLR
example (its dome firmware emulated on a pty, python-gphoto2 replaced at its API boundary by
tests/fake_gphoto2.py): each libgphoto2 code is said with what the user should do, naming the
camera (its model and USB port), and whether it took the picture only where the code tells.

Why: GP_ERROR (-1, libgphoto2's generic failure) at a capture said only "see `gphoto2 --debug`
output"; no capture failure said whether a picture had been taken, nor where it would be (the
camera's card, or its RAM, which keeps it only until the next capture).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from dng_spec_writer import dng, mosaic_from_rgb
from fake_gphoto2 import Body
from test_dslr_download_disk_full import _config, _raw, _shot_with

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

NOT_KNOWN = "whether it took the picture is not known"


def _busy_retries_spaced_short(cfg: Path) -> None:
    """The config's six busy retries spaced 0.01-0.02 s, not its 0.5 s to 4 s (15.5 s of
    real waiting per case): what is said once they are spent does not depend on the spacing,
    which tests/drivers/cameras/test_camera_gphoto2*.py check on an injected clock."""
    text = cfg.read_text()
    old = "busy_retries = 6\n"
    assert old in text
    cfg.write_text(text.replace(old, old + "retry_delay_s = 0.01\nretry_max_delay_s = 0.02\n"))


@pytest.mark.parametrize(
    ("code", "said_of_it"),
    [
        (-1, ["libgphoto2's generic error (GP_ERROR)", NOT_KNOWN, "--debug-logfile"]),
        (-7, ["USB I/O error with", "whether the camera took the picture is not known"]),
        (-53, ["is claimed by another program", "no picture was taken", "gio mount -s gphoto2"]),
        (-110, ["answered 'busy'", "normally takes no picture", "busy_retries"]),
    ],
)
@pytest.mark.parametrize("target", ["Internal RAM", "Memory card"])
def test_a_failed_capture_says_the_camera_what_to_do_and_what_is_known_of_the_picture(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, code: int, said_of_it: list[str], target: str
) -> None:
    cfg = _config(tmp_path, target)
    if code == -110:
        _busy_retries_spaced_short(cfg)
    body = Body(render=_raw, failures={"capture": [code] * 10})
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "2"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert body.shots == 0, said
    assert f"gphoto2 error {code}" in said, said
    assert "dslr (Canon EOS 600D on usb:001,005)" in said, said
    for words in said_of_it:
        assert words in said, (words, said)
    assert "see `gphoto2 --debug` output" not in said, said
    if code == -53:
        return  # never reached the camera: no card or RAM to look in
    if target == "Internal RAM":
        assert "a picture taken went into the camera's RAM" in said, said
        assert "it cannot be recovered" in said, said
    else:
        assert "a picture taken is on the camera's card" in said, said


def test_a_failed_capture_of_a_camera_left_at_its_own_target_names_no_place_as_known(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """capture_target = "" leaves the body's own target, which rti-rig never reads: a picture
    the failed capture may have taken is not said to be on the card (nor lost in RAM)."""
    cfg = _config(tmp_path, "")
    body = Body(render=_raw, failures={"capture": [-1] * 10})
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "2"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert NOT_KNOWN in said, said
    assert "a picture taken is on the camera's card" not in said, said
    assert "it cannot be recovered" not in said, said
    assert "where the camera's own capture target puts it" in said, said


def test_a_camera_claimed_by_gvfs_when_it_is_opened_is_named_with_the_commands_that_free_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """GP_ERROR_IO_USB_CLAIM (-53) comes where libgphoto2 claims the USB interface, as the
    camera is opened (``gp_camera_init``): a desktop's gvfs that mounted it refuses the run
    there, before any shot (gphoto2 #181, libgphoto2 #617). That refusal had said only "the
    USB device is claimed by another program …: stop that program or unmount the camera",
    naming neither the camera nor a command that frees it."""
    cfg = _config(tmp_path, "Memory card")
    body = Body(render=_raw, failures={"init": [-53]})
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "2"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert body.shots == 0 and "Nothing was captured" in said, said
    assert "gphoto2 error -53" in said, said
    assert "the USB device of dslr (Canon EOS 600D on usb:001,005) is claimed" in said, said
    assert "so rti-rig could not open it" in said and "no picture was taken" not in said, said
    assert "`gio mount -s gphoto2`" in said, said
    assert "`systemctl --user stop gvfs-gphoto2-volume-monitor`" in said, said


def test_a_camera_claimed_at_a_download_names_the_download_not_the_opening(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The camera's USB device claimed by another program as the first shot downloads (a file
    manager mounting the card once the shot appears): the words name the download that did
    not reach the camera; they had said "so rti-rig could not open it" of a camera it had
    opened and shot with."""
    cfg = _config(tmp_path, "Memory card")
    body = Body(render=_raw, failures={"file_get": [-53]})
    out = tmp_path / "s"
    r, said, _ = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "2"]
    )
    assert r.exit_code == 2 and "Traceback" not in said, said
    assert "gphoto2 error -53" in said and "is claimed by another program" in said, said
    assert "so its download call did not reach the camera" in said, said
    assert "could not open it" not in said, said


def test_a_busy_camera_retried_until_it_shot_is_said_with_the_shots_it_concerns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A body still writing its previous file answers the next two captures busy (-110, PTP
    Device Busy) and takes the third: the shot is taken, and the run had said nothing of the
    retries, whose waits lengthen every step of a session on a slow card."""
    cfg = _config(tmp_path, "Memory card")
    _busy_retries_spaced_short(cfg)
    body = Body(render=_raw, busy_after_shot=2)
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch,
        cfg,
        body,
        ["run", str(cfg), "--out", str(out), "--lights", "3", "--no-verdict"],
    )
    assert r.exit_code == 0 and "Traceback" not in said and lit_at_end is None, said
    assert body.shots == 3 and body.calls.count("capture") == 7, body.calls
    notice = (
        "dslr (Canon EOS 600D on usb:001,005) answered busy (gphoto2 error -110, PTP Device "
        "Busy: still writing a previous file, or its autofocus searching) and was tried again "
        "until it took the shot, at most busy_retries = 6 tries a shot spaced 0.01 s to 0.02 s "
        "apart"
    )
    assert notice in said and "[2 of 3 images]" in said.split(notice, 1)[1], said
    steps = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    said_of = [any(n.startswith(notice) for n in st.get("notices", [])) for st in steps]
    assert said_of == [False, True, True], steps


def test_a_retried_code_other_than_busy_is_said_as_the_config_s_retry_codes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """retry_codes = [-110, -1] in the config, and the body answers the first shot's capture
    with -1 once: the shot is taken, and the notice names the config's retry codes. It had
    said every retried reply was -110, PTP Device Busy, of a -1 (libgphoto2's generic
    failure)."""
    cfg = _config(tmp_path, "Memory card")
    _busy_retries_spaced_short(cfg)
    cfg.write_text(
        cfg.read_text().replace(
            "busy_retries = 6\n", "busy_retries = 6\nretry_codes = [-110, -1]\n"
        )
    )
    body = Body(render=_raw, failures={"capture": [-1]})
    out = tmp_path / "s"
    r, said, _ = _shot_with(
        monkeypatch,
        cfg,
        body,
        ["run", str(cfg), "--out", str(out), "--lights", "2", "--no-verdict"],
    )
    assert r.exit_code == 0 and "Traceback" not in said, said
    assert "answered a gphoto2 error of retry_codes = [-110, -1] (-110 is PTP Device Busy" in said
    assert "answered busy (gphoto2 error -110" not in said, said


def test_a_raw_that_would_not_decode_is_left_on_the_card_as_its_error_says(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Shot to the card, the second RAW downloads as bytes LibRaw cannot read (a transfer
    damaged on the way, a format newer than this LibRaw). Its card copy had been deleted
    before the decode, while the error went on "if no other program opens the file either,
    it is damaged: copy it again from the camera's card": the one good copy was gone."""
    out, body, said = _second_raw_undecodable(tmp_path, monkeypatch, "Memory card")
    on_card = "/store_00020001/DCIM/100CANON/IMG_0002.CR2"
    assert f"the camera's copy stays on its card at {on_card}, not deleted" in said, said
    assert "IMG_0002.CR2" in body.card and body.deleted == ["IMG_0001.CR2"], body.deleted
    assert (out / "raw" / ".incoming" / "cap0002_IMG_0002.CR2").is_file()


def test_a_raw_of_another_size_is_named_where_it_is_kept_as_paths_that_paste(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The second RAW comes back another size (a setting changed on the camera): the run
    stops and keeps it under recovered/, named relative to the session folder ("kept as
    recovered/…/image_002.tif"), which names no file from where the user ran rti-rig."""
    cfg = _config(tmp_path, "Memory card")

    def render(b: Body) -> bytes:
        size = (32, 48) if b.shots < 1 else (40, 60)
        rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (*size, 3))
        return dng(mosaic_from_rgb(np.array(rgb), "RGGB", (0,) * 4, 4095), "RGGB", (0,) * 4, 4095)

    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, Body(render=render), ["run", str(cfg), "--out", str(out), "--lights", "2"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "image 2 came back 60×40 colour, but this session's images are 48×32" in said, said
    kept = said.split("(kept as ", 1)[1].split("); set the camera back", 1)[0]
    tiff, raw = kept.split(", the camera's own file(s) as ")
    assert Path(tiff).is_absolute() and Path(tiff).is_file(), said
    assert Path(raw).is_absolute() and Path(raw).read_bytes() == render(Body(render, shots=1))


def test_a_raw_that_would_not_decode_shot_to_ram_is_not_sent_to_the_card(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Shot to the camera's RAM (the shipped DSLR example's target), a download LibRaw cannot
    read had been said "the camera's copy deleted" and, in the same sentence, "if no other
    program opens the file either, it is damaged: copy it again from the camera's card": a
    card that never held it."""
    out, _, said = _second_raw_undecodable(tmp_path, monkeypatch, "Internal RAM")
    assert "the camera's copy deleted." in said, said  # delete_from_camera, as shipped
    assert "from the camera's card" not in said, said
    assert (
        "it is damaged: there is no copy of it on the camera to copy again; the kept file is the "
        "only one, and a resumed session shoots this image again"
    ) in said, said
    assert (out / "raw" / ".incoming" / "cap0002_IMG_0002.CR2").is_file()


def _second_raw_undecodable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, target: str
) -> tuple[Path, Body, str]:
    """A 2-light run shot to ``target`` whose second RAW downloads as bytes LibRaw cannot
    read: the session folder, the camera body and what the run said (checked to have
    stopped on that RAW, lights off, no traceback)."""
    cfg = _config(tmp_path, target)
    body = Body(render=lambda b: _raw(b) if b.shots < 1 else b"II*\x00damaged" * 100)
    out = tmp_path / "s"
    r, said, lit_at_end = _shot_with(
        monkeypatch, cfg, body, ["run", str(cfg), "--out", str(out), "--lights", "2"]
    )
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert "the camera's file IMG_0002.CR2 would not decode" in said, said
    return out, body, said
