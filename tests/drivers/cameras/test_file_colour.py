"""What a JPEG or TIFF says of its colour space is read as said (ICC profile description,
else Exif ColorSpace with the InteroperabilityIndex), or found to say nothing.

Why: every non-RAW file was declared sRGB, an Adobe RGB JPEG and a ProPhoto TIFF too. The
files are built in :mod:`colour_files` from the published layouts (sources cited there).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tifffile
from colour_files import exif_colour, icc_profile, jpeg, png

from rti_rig.drivers.cameras.file_colour import file_colour


@pytest.mark.parametrize(
    ("data", "space", "said"),
    [
        (jpeg(exif=exif_colour(1)), "srgb", "Exif ColorSpace 1"),
        (jpeg(exif=exif_colour(0xFFFF, b"R03\0")), "adobe_rgb", "InteroperabilityIndex R03"),
        (jpeg(exif=exif_colour(0xFFFF, b"R98\0")), "other", "uncalibrated"),
        (jpeg(icc=icc_profile("Adobe RGB (1998)")), "adobe_rgb", "'Adobe RGB (1998)'"),
        (jpeg(icc=icc_profile("Display P3", version4=True)), "display_p3", "'Display P3'"),
        # an ICC profile wins over the Exif ColorSpace (what colour-managed software obeys)
        (
            jpeg(exif=exif_colour(1), icc=icc_profile("ProPhoto RGB")),
            "prophoto",
            "'ProPhoto RGB'",
        ),
        (jpeg(icc=icc_profile("My scanner profile")), "other", "'My scanner profile'"),
        (jpeg(), "untagged", ""),
    ],
)
def test_a_jpeg_says_its_space(tmp_path: Path, data: bytes, space: str, said: str) -> None:
    path = tmp_path / "IMG_0001.JPG"
    path.write_bytes(data)
    found = file_colour(path)
    assert found.space == space
    assert said in found.said_by


def test_a_tiff_says_its_space_by_its_icc_profile(tmp_path: Path) -> None:
    """A 16-bit TIFF with an embedded ProPhoto profile (Lightroom's default export) is
    ProPhoto; one with none says nothing."""
    pixels = np.full((8, 8, 3), 20000, np.uint16)
    tagged, bare = tmp_path / "a.tif", tmp_path / "b.tif"
    tifffile.imwrite(tagged, pixels, iccprofile=icc_profile("ProPhoto RGB"))
    tifffile.imwrite(bare, pixels)
    found = file_colour(tagged)
    assert (found.space, found.name) == ("prophoto", "ProPhoto RGB (ROMM RGB)")
    assert file_colour(bare).space == "untagged"


@pytest.mark.parametrize(
    ("data", "space"),
    [
        (png(srgb=True), "srgb"),
        (png(icc=icc_profile("Adobe RGB (1998)")), "adobe_rgb"),
        (png(), "untagged"),
    ],
)
def test_a_png_says_its_space(tmp_path: Path, data: bytes, space: str) -> None:
    """A PNG's sRGB chunk or iCCP profile is read too (a watched folder takes PNGs)."""
    path = tmp_path / "shot.png"
    path.write_bytes(data)
    assert file_colour(path).space == space
