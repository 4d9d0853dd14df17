"""`rti-rig plan PREVIEW` reads a preview's brightness through its file's own colour space: a
ProPhoto 16-bit TIFF's gamma 1.8 and a 16-bit sRGB-encoded TIFF's sRGB curve are undone before
the planner estimates the light and the relief, and the plan says so.

Why: a preview was read through the sRGB curve (8-bit) or as linear (16-bit) whatever its
file said: the shading of a ProPhoto export of the sphere below, flattened by its gamma, gave
a light 10° higher (elevation 39.9° against 30.0°) and a relief 7° flatter than its linear
light does. Each test plans the tagged preview and the same shading in a linear 16-bit
TIFF that says nothing (linearised here by the specs' published curves: ROMM RGB, ISO
22028-2, E'^1.8; sRGB, IEC 61966-2-1 5.3): a grey keeps its value through any
primaries, so the two plans agree only if the tagged file's curve was undone. Files built in
:mod:`colour_files` (sources cited there).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import tifffile
from colour_files import icc_profile, raw_converter_tiff
from conftest import planned_preview


def _sphere() -> np.ndarray:
    """A matte grey sphere (48 px) lit from azimuth 30°, elevation 40°: linear, 0..1, RGB."""
    y, x = np.mgrid[-1:1:48j, -1:1:48j]
    z = np.sqrt(np.clip(1 - x**2 - y**2, 0, 1))
    el, az = math.radians(40), math.radians(30)
    light = (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
    shade = np.clip(x * light[0] - y * light[1] + z * light[2], 0, 1) * (z > 0) * 0.8 + 0.02
    return np.repeat(shade[..., None], 3, axis=2)


def _plan(preview: Path) -> tuple[tuple[float, ...], str]:
    """The plan's estimated light (az, el) and RMS relief tilt, and all it said."""
    said = planned_preview(preview, preview.with_suffix(".lp"))
    light = re.search(r"preview light az ([\d.-]+)°, el ([\d.-]+)°", said)
    tilt = re.search(r"RMS tilt ([\d.]+)°", said)
    assert light and tilt, said
    return (float(light[1]), float(light[2]), float(tilt[1])), said


def _prophoto(tmp_path: Path) -> tuple[Path, Path, Path]:
    encoded = np.round(_sphere() ** (1 / 1.8) * 65535).astype(np.uint16)
    tagged, untagged = tmp_path / "prophoto.tif", tmp_path / "untagged.tif"
    tifffile.imwrite(tagged, encoded, iccprofile=icc_profile("ProPhoto RGB"))
    tifffile.imwrite(untagged, encoded)
    linear = tmp_path / "linear.tif"  # E' >= 1/32 throughout: E'^1.8
    tifffile.imwrite(linear, np.round((encoded / 65535) ** 1.8 * 65535).astype(np.uint16))
    return tagged, untagged, linear


def _srgb_16_bit(tmp_path: Path) -> tuple[Path, Path, Path]:
    """A 16-bit sRGB-encoded export (an sRGB profile whose curve is the sRGB curve's)."""
    v = _sphere()
    encoded = np.where(v <= 0.0031308, v * 12.92, 1.055 * v ** (1 / 2.4) - 0.055)
    codes = np.round(encoded * 65535).astype(np.uint16)
    tagged, untagged = tmp_path / "srgb16.tif", tmp_path / "untagged.tif"
    tifffile.imwrite(tagged, codes, iccprofile=icc_profile("sRGB IEC61966-2.1"))
    tifffile.imwrite(untagged, codes)
    e = codes / 65535  # IEC 61966-2-1, 5.3
    decoded = np.where(e <= 0.04045, e / 12.92, ((e + 0.055) / 1.055) ** 2.4)
    linear = tmp_path / "linear.tif"
    tifffile.imwrite(linear, np.round(decoded * 65535).astype(np.uint16))
    return tagged, untagged, linear


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (_prophoto, "is ProPhoto RGB (ROMM RGB) (said by its ICC profile 'ProPhoto RGB')"),
        (_srgb_16_bit, "is sRGB (said by its ICC profile 'sRGB IEC61966-2.1')"),
    ],
)
def test_a_preview_is_read_through_its_own_colour_space(tmp_path, make, words) -> None:
    tagged, untagged, linear = make(tmp_path)
    got, said = _plan(tagged)
    want, _ = _plan(linear)
    as_untagged, _ = _plan(untagged)
    # the curve matters on this sphere (the test could tell): the untagged reading is off
    assert abs(as_untagged[1] - want[1]) > 3 or abs(as_untagged[2] - want[2]) > 3, as_untagged
    assert np.allclose(got, want, atol=0.3), (got, want)
    assert f"preview {tagged} {words}: its brightness is read in linear sRGB" in said, said


def test_a_linear_preview_with_the_camera_s_exif_srgb_is_read_as_linear(tmp_path) -> None:
    """A raw converter's linear TIFF carrying the camera's Exif ColorSpace 1 and no ICC
    profile (colour_files.raw_converter_tiff) plans as the same pixels without the tag do, and
    the plan says how it read it; its sRGB curve had been undone, the sphere's shading
    darkened."""
    codes = np.round(_sphere() * 65535).astype(np.uint16)
    tagged, bare = tmp_path / "dcraw.tif", tmp_path / "bare.tif"
    raw_converter_tiff(tagged, codes)
    raw_converter_tiff(bare, codes, colorspace=None)
    got, said = _plan(tagged)
    want, _ = _plan(bare)
    assert np.allclose(got, want, atol=0.05), (got, want)
    assert f"preview {tagged} is 16-bit, says sRGB only by its Exif ColorSpace 1" in said


def test_a_preview_s_out_of_gamut_pixels_are_counted(tmp_path) -> None:
    """An Adobe RGB preview with a square of its own pure green, which sRGB cannot show: the
    plan says how many pixels were clipped (a session's frame's are counted: folder_watch,
    fit); the plan had said nothing of them. A grey preview of the same space says none."""
    codes = np.round(_sphere() ** (256 / 563) * 65535).astype(np.uint16)
    grey = tmp_path / "grey.tif"
    tifffile.imwrite(grey, codes, iccprofile=icc_profile("Adobe RGB (1998)"))
    codes[:8, :8] = (0, 65535, 0)
    green = tmp_path / "green.tif"
    tifffile.imwrite(green, codes, iccprofile=icc_profile("Adobe RGB (1998)"))
    _, said = _plan(green)
    assert "its primaries converted to sRGB's; 64 of its 2304 pixels lie outside sRGB's" in said
    _, said = _plan(grey)
    assert "converted to sRGB's" in said and "outside sRGB's gamut" not in said, said
