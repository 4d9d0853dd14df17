"""A JPEG or TIFF preview marked as taken turned says it is planned in stored pixel order.

A session's JPEGs and TIFFs are recorded as stored (folder_watch says so of a turned camera),
so a preview is planned in the same frame; but a phone preview marked "rotate 90°" had been
planned sideways to the picture a viewer shows, with not a word.
"""

from __future__ import annotations

import io
import struct
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import planned_preview


def _shading() -> np.ndarray:
    ramp = np.linspace(40, 200, 48, dtype=np.float64)
    return np.repeat((ramp[:, None] + ramp[None, :]) / 2, 3).reshape(48, 48, 3).astype(np.uint8)


def _jpeg(orientation: int) -> bytes:
    """A JPEG whose EXIF IFD0 holds ``orientation``."""
    ok, encoded = cv2.imencode(".jpg", _shading())
    assert ok
    tiff = b"MM\0*" + struct.pack(">I", 8) + struct.pack(">H", 1)
    tiff += struct.pack(">HHIHH", 274, 3, 1, orientation, 0) + struct.pack(">I", 0)
    app1 = b"Exif\0\0" + tiff
    data = encoded.tobytes()
    return data[:2] + b"\xff\xe1" + struct.pack(">H", len(app1) + 2) + app1 + data[2:]


def _tiff(orientation: int) -> bytes:
    import tifffile

    buffer = io.BytesIO()
    tifffile.imwrite(
        buffer, _shading().astype(np.uint16) * 257, extratags=[(274, 3, 1, orientation, True)]
    )
    return buffer.getvalue()


def _plan(tmp_path: Path, name: str, data: bytes) -> str:
    preview = tmp_path / name
    preview.write_bytes(data)
    return planned_preview(preview, tmp_path / "p.lp", "--preview-light", "0,90")


@pytest.mark.parametrize(
    ("name", "data", "words"),
    [
        ("phone.jpg", _jpeg(6), "Orientation tag 6: rotate 90° CW to view"),
        ("scan.tif", _tiff(8), "Orientation tag 8: rotate 90° CCW to view"),
    ],
)
def test_a_turned_preview_is_said_planned_as_stored(
    tmp_path: Path, name: str, data: bytes, words: str
) -> None:
    said = _plan(tmp_path, name, data)
    assert f"the preview {name} is marked as taken turned ({words})" in said
    assert "stored pixel order" in said


@pytest.mark.parametrize(
    ("name", "data", "words"),
    [
        ("selfie.jpg", _jpeg(2), "Orientation tag 2: mirrored horizontally"),
        (
            "scan.tif",
            _tiff(5),
            "Orientation tag 5: mirrored across the top-left to bottom-right diagonal",
        ),
    ],
)
def test_a_mirrored_preview_is_said_mirrored_not_turned(
    tmp_path: Path, name: str, data: bytes, words: str
) -> None:
    """Orientations 2, 4, 5 and 7 flip the picture: they had been said "taken turned" (and 5
    and 7 only "transposed"), which a user would undo by turning the camera, not flipping."""
    said = _plan(tmp_path, name, data)
    assert f"the preview {name} is marked as mirrored ({words}" in said, said
    assert "not flipped back as a viewer shows it" in said, said
    assert "taken turned" not in said, said


def test_an_upright_preview_says_nothing_of_it(tmp_path: Path) -> None:
    said = _plan(tmp_path, "upright.jpg", _jpeg(1))
    assert "taken turned" not in said
