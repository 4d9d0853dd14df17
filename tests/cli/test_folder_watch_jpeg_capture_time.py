"""A camera's JPEGs in a watched folder (``eight_bit_response = "srgb"``) are checked against
the shutter pulses by their EXIF DateTimeOriginal, through `rti-rig run` on the shipped
folder-watch example (its dome firmware emulated on a pty, its camera a thread that saves a
JPEG into the watched folder for each shutter pulse the board saw).

Why: a JPEG's capture time was never read (only a RAW's and a TIFF's were): every image was
said to come from a file that "holds no capture time (no EXIF DateTimeOriginal ...)" though
each held one, and an extra JPEG that came after a pulse (an earlier shot the tethering
program saved late) was taken as that light's image, its own shot then as the next light's.
Nor was a JPEG's EXIF Orientation read: a camera held on its side gave images recorded as stored
(sideways beside the folder's file a viewer turns upright) with not a word, where a rotated
RAW's are said to be kept in sensor orientation. And a JPEG refused as 8-bit (the example's
default) is told with the table of the key that takes it, and where the shot was left.
"""

from __future__ import annotations

import shutil
import struct
import sys
import threading
import time
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import CONFIGS, folder_watch_config, shipped_dome_on_pty, tethered_run
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.shell_words import shown_path

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

WATCH_CONFIG = CONFIGS / "example_dome_48_folder_watch.toml"
#: the camera clock's reading at the board clock's zero (only differences are checked)
CAMERA_EPOCH = 1_780_000_000.0


def _config(tmp_path: Path, tether: Path, eight_bit: bool = True) -> Path:
    """The shipped example beside its .lp, watching ``tether`` for the camera's JPEGs (taken
    as sRGB where ``eight_bit``, else refused as the example's default does)."""
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = WATCH_CONFIG.read_text()
    for old, new in [
        ('folder = "~/Pictures/rti-tether"', f'folder = "{tether}"'),
        ("timeout_s = 15.0", "timeout_s = 4.0" + ('\neight_bit_response = "srgb"' * eight_bit)),
        ("width = 6000", "width = 32"),
        ("height = 4000", "height = 32"),
    ]:
        assert old in text
        text = text.replace(old, new)
    text = (
        text[: text.index("patterns = ")]
        + 'patterns = ["*.JPG"]\n'
        + text[text.index("\n", text.index("patterns = ")) + 1 :]
    )
    cfg = tmp_path / "watch.toml"
    cfg.write_text(text)
    return cfg


def _jpeg(level: int, taken: float, orientation: int = 1) -> bytes:
    """A camera JPEG of one grey ``level`` whose IFD0 holds ``orientation`` and whose Exif IFD
    holds DateTimeOriginal ``taken``."""
    ok, encoded = cv2.imencode(".jpg", np.full((32, 32, 3), level, np.uint8))
    assert ok
    stamp = time.strftime("%Y:%m:%d %H:%M:%S", time.gmtime(taken)).encode() + b"\0"
    # big-endian TIFF: IFD0 (Orientation; the Exif IFD at 38), Exif IFD (DateTimeOriginal at 56)
    tiff = b"MM\0*" + struct.pack(">I", 8) + struct.pack(">H", 2)
    tiff += struct.pack(">HHIHH", 274, 3, 1, orientation, 0)
    tiff += struct.pack(">HHII", 0x8769, 4, 1, 38) + struct.pack(">I", 0)
    tiff += struct.pack(">H", 1) + struct.pack(">HHII", 0x9003, 2, 20, 56) + struct.pack(">I", 0)
    app1 = b"Exif\0\0" + tiff + stamp
    segment = b"\xff\xe1" + struct.pack(">H", len(app1) + 2) + app1
    data = encoded.tobytes()
    return data[:2] + segment + data[2:]


def test_an_extra_jpeg_after_a_pulse_is_set_aside_and_a_rotated_one_is_said(tmp_path, monkeypatch):
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = _config(tmp_path, tether)
    own: dict[int, bytes] = {}
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        stop = threading.Event()

        def tethering_program() -> None:
            saved = 0
            while not stop.is_set():
                pulses = [e.time_s for e in list(firmware.history) if e.what == "shutter"]
                if len(pulses) > saved:
                    saved += 1
                    taken = CAMERA_EPOCH + pulses[-1]
                    if saved == 2:  # a shot from a minute before, saved late, comes first
                        (tether / "IMG_0100.JPG").write_bytes(_jpeg(250, taken - 60))
                        stop.wait(0.3)
                    own[saved] = _jpeg(40 * saved, taken, orientation=6)  # held on its side
                    (tether / f"IMG_{saved:04d}.JPG").write_bytes(own[saved])
                stop.wait(0.01)

        thread = threading.Thread(target=tethering_program, daemon=True)
        thread.start()
        out = tmp_path / "s"
        try:
            r = CliRunner().invoke(
                app, ["run", str(cfg), "--out", str(out), "--lights", "3", "--no-verdict"]
            )
        finally:
            stop.set()
            thread.join(5)
        lit_at_end = firmware.lit
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    assert lit_at_end is None and "lights are off" in said, said
    assert "holds no capture time" not in said, said
    for k in (1, 2, 3):  # each light's image is the shot of its own pulse
        assert (out / "raw" / f"image_{k:03d}.jpg").read_bytes() == own[k], k
    assert [p.name for p in (out / "strays").iterdir()] == ["image_002-IMG_0100.JPG"], said
    assert (
        "the camera was rotated (Orientation tag 6: rotate 90° CW to view): rti-rig keeps the "
        "JPEG's pixels as stored" in said
    ), said
    assert "fitting is unaffected (docs/cameras.md) [3 of 3 images]" in said, said
    # the stray is never one of the session's lights: export-lp (JPEGs and --linear) lists the
    # three images with the lights lights.lp gives them, read back by the tolerant reader
    from rti_rig.core.lp_format import read_lp

    fired = [e.direction for e in read_lp(out / "lights.lp")]
    for args, names in (([], "image_{:03d}.jpg"), (["--linear"], "linear/image_{:03d}.tif")):
        lp = tmp_path / f"export{len(args)}.lp"
        done = CliRunner().invoke(app, ["export-lp", str(out), "--out", str(lp), *args])
        assert done.exit_code == 0, done.output
        entries = read_lp(lp)
        assert [e.name for e in entries] == [names.format(k) for k in (1, 2, 3)], entries
        assert [e.direction for e in entries] == fired


def test_a_refused_jpeg_names_the_key_its_table_and_where_the_shot_is_left(tmp_path, monkeypatch):
    """The refusal of an 8-bit file said "set eight_bit_response = 'srgb'", not in which
    table, nor that the shot is still in the folder (the run had just said "Nothing was
    captured")."""
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = _config(tmp_path, tether, eight_bit=False)
    files = [("IMG_0001.JPG", _jpeg(100, CAMERA_EPOCH))]
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, tmp_path / "s")
    assert r.exit_code == 2 and "Traceback" not in said, said
    assert not lit_at_end and "lights are off" in said, said
    assert 'add eight_bit_response = "srgb" under [camera.device] in the rig config' in said, said
    assert f"IMG_0001.JPG is left in {shown_path(tether)}" in said, said
    assert (tether / "IMG_0001.JPG").read_bytes() == files[0][1]


@pytest.mark.parametrize(
    ("tag", "words"),
    [
        (8, "the camera was rotated (Orientation tag 8: rotate 90° CCW to view)"),
        (
            7,
            "the picture is marked mirrored (Orientation tag 7: mirrored across the top-right "
            "to bottom-left diagonal (transversed))",
        ),
    ],
)
def test_a_rotated_16_bit_tiff_is_said_kept_as_stored(tmp_path, monkeypatch, tag, words):
    """A 16-bit TIFF saved with its camera's Orientation 8 (tifffile reads it as stored, as
    OpenCV reads a JPEG) gets the rotated-camera notice; it had been recorded with none. A
    mirrored one (7) is said mirrored: it had been said to come from a rotated camera."""
    import io

    import tifffile

    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0, tiffs=True)
    buffer = io.BytesIO()
    tifffile.imwrite(
        buffer, np.full((32, 32, 3), 20000, np.uint16), extratags=[(274, 3, 1, tag, True)]
    )
    files = [(f"IMG_{k:04d}.tif", buffer.getvalue()) for k in (1, 2)]
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, tmp_path / "s")
    assert r.exit_code == 0 and "Traceback" not in said, said
    assert not lit_at_end and "lights are off" in said, said
    assert f"{words}: rti-rig keeps the TIFF's pixels as stored" in said, said
    assert "fitting is unaffected (docs/cameras.md) [2 of 2 images]" in said, said
