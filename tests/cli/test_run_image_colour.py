"""A session's images say what colour they are, read back as viewers read them.

Before: the JPEGs carried no colour tag (no Exif ColorSpace, no ICC profile) and the linear
TIFFs only tifffile's ``{"shape": ...}``, so viewers took the TIFFs as sRGB-encoded and showed
them dark; a RAW with no colour matrix gave camera-RGB JPEGs with no word on the terminal,
while the guide called them "true sRGB". The segments and tags are parsed here, by the
standards (JPEG APP1 Exif / APP2 ICC_PROFILE, TIFF tag 34675, ICC.1 header and curv), not
by the code that writes them.
"""

from __future__ import annotations

import struct
from pathlib import Path

import cv2
import numpy as np
import pytest
import tifffile
from conftest import manifest, said, shipped_variant
from typer.testing import CliRunner

from rti_rig.cli import app

SMALL = (("width = 512\nheight = 512", "width = 64\nheight = 64"),)
RAW = ("noise = true", "noise = true\nraw = true")


def _segments(jpeg: bytes) -> list[tuple[int, bytes]]:
    """The (marker, body) of each JPEG segment before the first scan."""
    out, pos = [], 2
    while jpeg[pos] == 0xFF and jpeg[pos + 1] != 0xDA:
        length = int.from_bytes(jpeg[pos + 2 : pos + 4], "big")
        out.append((jpeg[pos + 1], jpeg[pos + 4 : pos + 2 + length]))
        pos += 2 + length
    out.append((0xDA, b""))
    return out


def _without_app1_app2(jpeg: bytes) -> bytes:
    """``jpeg`` with its APP1 and APP2 segments (Exif, ICC profile) cut out."""
    out, pos = [jpeg[:2]], 2
    while jpeg[pos + 1] != 0xDA:
        end = pos + 2 + int.from_bytes(jpeg[pos + 2 : pos + 4], "big")
        if jpeg[pos + 1] not in (0xE1, 0xE2):
            out.append(jpeg[pos:end])
        pos = end
    return b"".join(out) + jpeg[pos:]


def _ifd(t: bytes, o: str, at: int) -> dict[int, bytes]:
    """A TIFF IFD's entries at ``at``: tag -> its 4-byte value field (byte order ``o``)."""
    n = struct.unpack_from(o + "H", t, at)[0]
    return {
        struct.unpack_from(o + "H", t, at + 2 + 12 * i)[0]: t[at + 10 + 12 * i : at + 14 + 12 * i]
        for i in range(n)
    }


def _exif_colorspace(jpeg: bytes) -> int | None:
    """Exif ColorSpace (tag 0xA001 in the Exif IFD that IFD0's tag 0x8769 points to)."""
    for marker, body in _segments(jpeg):
        if marker == 0xE1 and body.startswith(b"Exif\0\0"):
            t = body[6:]
            o = "<" if t[:2] == b"II" else ">"
            ifd0 = _ifd(t, o, struct.unpack_from(o + "I", t, 4)[0])
            exif = _ifd(t, o, struct.unpack_from(o + "I", ifd0[0x8769])[0])
            return struct.unpack_from(o + "H", exif[0xA001])[0]
    return None


def _jpeg_icc(jpeg: bytes) -> bytes | None:
    for marker, body in _segments(jpeg):
        if marker == 0xE2 and body.startswith(b"ICC_PROFILE\0"):
            assert body[12:14] == b"\x01\x01"  # one chunk of one
            return body[14:]
    return None


def _icc_tags(icc: bytes) -> dict[bytes, bytes]:
    """An ICC profile's tags by signature, after checking its header (ICC.1 §7.2)."""
    assert struct.unpack(">I", icc[:4])[0] == len(icc)
    assert icc[36:40] == b"acsp" and icc[16:20] == b"RGB " and icc[20:24] == b"XYZ "
    n = struct.unpack(">I", icc[128:132])[0]
    tags = {}
    for i in range(n):
        sig, off, size = struct.unpack(">4sII", icc[132 + 12 * i : 144 + 12 * i])
        assert off % 4 == 0 and off + size <= len(icc)
        tags[sig] = icc[off : off + size]
    return tags


def _curve(tag: bytes) -> list[float]:
    assert tag[:4] == b"curv"
    n = struct.unpack(">I", tag[8:12])[0]
    return (
        [v / 65535 for v in struct.unpack(f">{n}H", tag[12 : 12 + 2 * n])]
        if n > 1
        else [struct.unpack(">H", tag[12:14])[0] / 256]
    )


def _xyz(tag: bytes) -> np.ndarray:
    assert tag[:4] == b"XYZ "
    return np.array(struct.unpack(">3i", tag[8:20])) / 65536


@pytest.fixture(scope="module")
def sessions(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, str]]:
    """The shipped simulated dome at 64 px, 2 lights, as shipped and with ``[scene] raw =
    true`` (a DNG with no colour matrix through the real RAW decode): folder and output."""
    out = {}
    for kind, edits in (("plain", SMALL), ("raw", (*SMALL, RAW))):
        folder = tmp_path_factory.mktemp(kind)
        config = shipped_variant(folder, "simulated_dome.toml", edits)
        r = CliRunner().invoke(
            app, ["run", str(config), "--out", str(folder / "s"), "--lights", "2", "--no-verdict"]
        )
        assert r.exit_code == 0, r.output
        out[kind] = (folder / "s", said(r))
    return out


def test_a_session_jpeg_is_tagged_srgb_and_its_pixels_are_unchanged(sessions) -> None:
    session, _ = sessions["plain"]
    jpeg = (session / "image_001.jpg").read_bytes()
    markers = [m for m, _ in _segments(jpeg)]
    assert markers[0] == 0xE0 and 0xC0 in markers and 0xC2 not in markers  # JFIF, baseline
    assert _exif_colorspace(jpeg) == 1
    tags = _icc_tags(_jpeg_icc(jpeg))
    assert b"sRGB" in tags[b"desc"]
    curve = np.array(_curve(tags[b"rTRC"]))
    v = np.linspace(0, 1, len(curve))
    srgb = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    np.testing.assert_allclose(curve, srgb, atol=1 / 65535)
    white = _xyz(tags[b"rXYZ"]) + _xyz(tags[b"gXYZ"]) + _xyz(tags[b"bXYZ"])
    np.testing.assert_allclose(white, [0.9642, 1.0, 0.8249], atol=2e-4)  # D50, as ICC wants
    # the same pixels as the JPEG without the tags: only header segments were added
    bare = _without_app1_app2(jpeg)
    assert len(bare) < len(jpeg) and _exif_colorspace(bare) is None
    decoded = cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_UNCHANGED)
    np.testing.assert_array_equal(
        decoded, cv2.imdecode(np.frombuffer(bare, np.uint8), cv2.IMREAD_UNCHANGED)
    )


def test_a_session_linear_tiff_says_it_is_linear_and_the_manifest_agrees(sessions) -> None:
    session, _ = sessions["plain"]
    with tifffile.TiffFile(session / "linear" / "image_001.tif") as tif:
        page = tif.pages.first
        assert page.description.startswith("rti-rig: linear sRGB"), page.description
        assert "NOT sRGB-encoded" in page.description
        tags = _icc_tags(page.tags[34675].value)
    assert _curve(tags[b"rTRC"]) == [1.0]  # gamma 1.0: linear
    assert b"Linear" in tags[b"desc"]
    jpeg_tags = _icc_tags(_jpeg_icc((session / "image_001.jpg").read_bytes()))
    for primary in (b"rXYZ", b"gXYZ", b"bXYZ"):  # the same colours as the JPEG
        np.testing.assert_array_equal(_xyz(tags[primary]), _xyz(jpeg_tags[primary]))
    colour = manifest(session)["image_colour"]
    assert colour["linear"].startswith("linear sRGB") and "ICC" in colour["linear"]
    assert ") (" not in colour["linear"], colour  # one sentence, not two parentheticals
    assert colour["jpeg"].startswith("sRGB") and "ColorSpace 1" in colour["jpeg"]


def test_a_raw_without_a_colour_matrix_is_said_once_and_not_tagged_srgb(sessions) -> None:
    session, output = sessions["raw"]
    assert output.count("camera RGB, not sRGB") == 1, output
    assert "colour matrix" in output and "[2 of 2 images]" in output, output
    jpeg = (session / "image_001.jpg").read_bytes()
    assert _exif_colorspace(jpeg) is None and _jpeg_icc(jpeg) is None
    with tifffile.TiffFile(session / "linear" / "image_001.tif") as tif:
        page = tif.pages.first
        assert 34675 not in page.tags
        assert page.description.startswith("rti-rig: linear camera RGB"), page.description
    m = manifest(session)
    assert m["steps"][0]["decode"]["color_space"].startswith("camera RGB")
    assert "NOT sRGB" in m["image_colour"]["jpeg"]
    assert m["image_colour"]["linear"].startswith("linear camera RGB")
    assert any("camera RGB, not sRGB" in n for n in m["notices"])
