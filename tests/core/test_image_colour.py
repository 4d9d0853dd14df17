"""Which images are tagged sRGB and which are not, and that a tag changes no pixel.

Why: a RAW with no colour matrix (or ``output_color = "raw"``) gives camera RGB, which must
not be told sRGB; the decision is read from the decode record that raw_decode writes, so its
wording and :func:`decode_colour` are checked together on real DNG decodes.
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from rti_rig.core.devices import Frame
from rti_rig.core.image_colour import decode_colour, icc_profile, jpeg_colour_tags, tag_jpeg_srgb
from rti_rig.core.image_files import write_srgb_jpeg, write_untagged_jpeg


def _dng(with_matrix: bool) -> bytes:
    from dng_spec_writer import dng as spec_dng
    from dng_spec_writer import mosaic_from_rgb

    from rti_rig.drivers.cameras.raw_decode import XYZ_FROM_SRGB

    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.6]), (32, 48, 3))
    raw = mosaic_from_rgb(np.array(rgb), "RGGB", (0, 0, 0, 0), 16383)
    matrix = np.linalg.inv(XYZ_FROM_SRGB) if with_matrix else None
    return spec_dng(raw, "RGGB", (0, 0, 0, 0), 16383, color_matrix=matrix)


@pytest.mark.parametrize(
    ("with_matrix", "settings", "colour"),
    [
        (True, {}, "srgb"),
        (False, {}, "camera"),
        (True, {"output_color": "raw"}, "camera"),
        (True, {"mode": "mosaic"}, "mosaic"),
    ],
)
def test_decode_colour_follows_what_the_raw_decode_did(with_matrix, settings, colour) -> None:
    from rti_rig.drivers.cameras.raw_decode import decode_raw
    from rti_rig.drivers.cameras.settings import RawDecodeSettings

    frame = decode_raw(_dng(with_matrix), RawDecodeSettings(**settings))
    assert decode_colour(frame.metadata["decode"]) == colour


def test_an_image_not_from_a_raw_is_srgb() -> None:
    assert decode_colour({}) == "srgb"


def test_only_colour_srgb_jpegs_are_tagged_and_pixels_stay(tmp_path) -> None:
    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 256, (24, 32, 3), dtype=np.uint8)
    write_srgb_jpeg(tmp_path / "s.jpg", rgb)
    write_untagged_jpeg(tmp_path / "c.jpg", rgb)
    write_srgb_jpeg(tmp_path / "g.jpg", rgb[..., 0])  # grey: no RGB colour space to name
    tagged, plain = (tmp_path / "s.jpg").read_bytes(), (tmp_path / "c.jpg").read_bytes()
    assert jpeg_colour_tags(tagged) == {"exif_colorspace": 1, "icc_profile": icc_profile("srgb")}
    assert jpeg_colour_tags(plain) == {"exif_colorspace": None, "icc_profile": None}
    grey = (tmp_path / "g.jpg").read_bytes()
    assert jpeg_colour_tags(grey) == {"exif_colorspace": None, "icc_profile": None}
    assert tag_jpeg_srgb(plain) == tagged  # the tags are all that differ
    read = [cv2.imread(str(tmp_path / n), cv2.IMREAD_UNCHANGED) for n in ("s.jpg", "c.jpg")]
    np.testing.assert_array_equal(read[0], read[1])


@pytest.mark.parametrize(("decode", "tagged"), [({}, True), ({"mode": "mosaic"}, False)])
def test_an_unlabelled_image_is_tagged_as_its_decode_says(tmp_path, decode, tagged) -> None:
    from rti_rig.app.flash_sync import keep_unlabelled

    cam = {"mode": "demosaic", "color_space": "camera RGB (the file has no colour matrix)"}
    for d, t in ((decode, tagged), (cam, False)):
        px = np.full((8, 8, 3), 1000, np.uint16)
        frame = Frame(px, 0.1, 1.0, 65535, 0.0, {"decode": d} if d else {})
        rel = keep_unlabelled(tmp_path / str(t), 0, frame, {})
        jpeg = (tmp_path / str(t) / rel).with_suffix(".jpg").read_bytes()
        assert (jpeg_colour_tags(jpeg)["exif_colorspace"] == 1) is t
