"""A 16-bit RGB TIFF whose SamplesPerPixel tag is lost (its tag number damaged), saved into the
watched folder of the shipped folder-watch dome (its framed board emulated on a pty, the camera
and its tethering program a thread that saves one file for each shutter pulse the board saw):
``rti-rig run`` refuses it at the capture, naming the file and what its tags say, and records
no image for it.

tifffile reads such a file with TIFF's default of one sample per pixel, silently: the first
light's picture had gone into the session as a 64 x 64 grey image, and the next light's whole
RGB picture was then refused as "the camera's image size or format changed during the
session". A grey camera's TIFFs (PhotometricInterpretation MinIsBlack, one sample) are no
contradiction: such a session still runs to its end.
"""

from __future__ import annotations

import struct
import sys
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import tethered_tiffs

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _tiff(pixels: np.ndarray, photometric: str) -> bytes:
    """A plain 16-bit TIFF of ``pixels``, written by a program that records no shape of its
    own (no tifffile description: a camera's program, libtiff's way)."""
    from io import BytesIO

    out = BytesIO()
    tifffile.imwrite(out, pixels, photometric=photometric, metadata=None)
    return out.getvalue()


def _samples_lost(data: bytes) -> bytes:
    """``data`` with its SamplesPerPixel entry's tag number (277) damaged to an unknown one:
    the file's size, strips and every other tag as written."""
    raw = bytearray(data)
    ifd = struct.unpack_from("<I", raw, 4)[0]
    for k in range(struct.unpack_from("<H", raw, ifd)[0]):
        at = ifd + 2 + 12 * k
        if struct.unpack_from("<H", raw, at)[0] == 277:
            struct.pack_into("<H", raw, at, 0x7FFF)
            return bytes(raw)
    raise AssertionError("no SamplesPerPixel entry")


def test_run_refuses_an_rgb_tiff_whose_samples_per_pixel_is_lost(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rgb = np.full((64, 64, 3), 30000, np.uint16)
    rgb[..., 2] = 10000
    whole = _tiff(rgb, "rgb")
    damaged = _samples_lost(whole)
    r, said, tether, out, lit_at_end = tethered_tiffs(tmp_path, monkeypatch, [damaged, whole])
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert "IMG_0001.tif is a damaged TIFF" in said and "waiting will not help" in said, said
    assert f"cannot read image file {tether / 'IMG_0001.tif'} (" in said, said
    assert "PhotometricInterpretation says RGB" in said and "SamplesPerPixel" in said, said
    assert "one-channel image" in said, said
    assert f"left in {tether}" in said and "Save the shot again" in said, said
    assert "image size or format changed" not in said, said  # not blamed on the camera
    assert ".incoming" not in said, said
    assert not list((out / "linear").glob("image_*.tif")), said  # nothing recorded as image 1
    assert (tether / "IMG_0001.tif").read_bytes() == damaged  # left as the program saved it
    assert lit_at_end == []  # the dome was switched off


def test_a_grey_cameras_tiffs_still_make_a_session(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    grey = [_tiff(np.full((64, 64), v, np.uint16), "minisblack") for v in (20000, 25000)]
    r, said, _tether, out, lit_at_end = tethered_tiffs(tmp_path, monkeypatch, grey)
    assert r.exit_code == 0, said
    assert "damaged" not in said, said
    for n in (1, 2):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        assert image.shape == (64, 64), image.shape
    assert lit_at_end == []
