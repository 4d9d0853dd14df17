"""A watched folder's files are recorded in the colour space they say, through `rti-rig run`
on the shipped folder-watch example (its dome emulated on a pty, its camera a thread saving
a file per shutter pulse): the manifest's ``image_colour``, the linear TIFF's ICC tag and
ImageDescription, and the notice agree.

Why: any file not a RAW was declared sRGB: an Adobe RGB JPEG and a ProPhoto TIFF (Lightroom's
default export) had their linear TIFFs tagged with a linear-sRGB profile and the manifest said
"linear sRGB", and a file that says nothing was said to be sRGB rather than assumed so.
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np
import pytest
import tifffile
from colour_files import exif_colour, icc_profile, jpeg, raw_converter_tiff
from conftest import folder_watch_config, tethered_run

from rti_rig.core.image_colour import icc_profile as own_profile

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _linear(out: Path, stem: str) -> tifffile.TiffPage:
    """The first page of the session's linear TIFF of image ``stem`` (read, file closed)."""
    manifest = json.loads((out / "manifest.json").read_text())
    rel = next(s["linear_image"] for s in manifest["steps"] if Path(s["image"]).stem == stem)
    with tifffile.TiffFile(out / rel) as tif:
        page = tif.pages[0]
        return page.tags.get(34675), page.description


def test_adobe_rgb_and_untagged_jpegs_are_said_as_they_are(tmp_path, monkeypatch):
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0)
    text = cfg.read_text()
    start = text.index("patterns = [")
    text = text.replace(text[start : text.index("]\n", start) + 1], 'patterns = ["*.JPG"]')
    cfg.write_text(text.replace("timeout_s = 4.0", 'timeout_s = 4.0\neight_bit_response = "srgb"'))
    files = [
        ("IMG_0001.JPG", jpeg(90, exif=exif_colour(0xFFFF, b"R03\0"))),  # a camera's Adobe RGB
        ("IMG_0002.JPG", jpeg(90)),  # says nothing
    ]
    out = tmp_path / "s"
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, out)
    assert r.exit_code == 0 and "Traceback" not in said and not lit_at_end, said
    colour = json.loads((out / "manifest.json").read_text())["image_colour"]
    first, second = sorted(
        json.loads((out / "manifest.json").read_text())["steps"], key=lambda s: s["index"]
    )
    adobe, bare = Path(first["image"]).stem, Path(second["image"]).stem
    assert "converted from Adobe RGB (1998)" in colour["linear"], colour
    assert "assumed sRGB (the file does not say)" in colour["linear"], colour
    assert colour["linear"].index(adobe) > colour["linear"].index("Adobe RGB"), colour
    assert "sRGB, converted from Adobe RGB (1998)" in colour["jpeg"], colour
    icc, description = _linear(out, adobe)
    assert icc is not None and "converted from Adobe RGB (1998)" in description
    assert "InteroperabilityIndex R03" in description, description
    assert "gamma 563/256" in first["file_colour"]["curve_undone"], first
    icc, description = _linear(out, bare)
    assert icc is not None and "assumed sRGB (the file does not say)" in description
    # grey 90 stays grey; undone by Adobe RGB's gamma 563/256, not by the sRGB curve
    grey = tifffile.imread(out / first["linear_image"])[8, 8]
    assert np.allclose(grey, (90 / 255) ** (563 / 256) * 65535, atol=3), grey
    assert "the camera's files are Adobe RGB (1998) (said by" in said, said
    assert "converted its primaries to sRGB's" in said, said
    assert "assumed sRGB (the file does not say)" in said, said


def test_a_prophoto_16_bit_tiff_is_made_linear_srgb(tmp_path, monkeypatch):
    """Lightroom's default export, ProPhoto at gamma 1.8, had been taken as linear: its grey
    20000 is 7743 once ROMM RGB's curve is undone (ISO 22028-2: E'^1.8)."""
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0, tiffs=True)
    buffer = io.BytesIO()
    tifffile.imwrite(
        buffer, np.full((32, 32, 3), 20000, np.uint16), iccprofile=icc_profile("ProPhoto RGB")
    )
    files = [(f"IMG_{k:04d}.tif", buffer.getvalue()) for k in (1, 2)]
    out = tmp_path / "s"
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, out)
    assert r.exit_code == 0 and "Traceback" not in said and not lit_at_end, said
    colour = json.loads((out / "manifest.json").read_text())["image_colour"]
    assert colour["linear"].startswith("linear sRGB"), colour
    assert "converted from ProPhoto RGB (ROMM RGB)" in colour["linear"], colour
    step = json.loads((out / "manifest.json").read_text())["steps"][0]
    assert "gamma 1.8" in step["file_colour"]["curve_undone"], step
    assert step["file_colour"]["out_of_gamut_clipped"] == "0 of 1024 pixels", step
    icc, description = _linear(out, Path(step["image"]).stem)
    assert icc is not None and "converted from ProPhoto RGB (ROMM RGB)" in description
    assert "its ICC profile 'ProPhoto RGB'" in description, description
    pixels = tifffile.imread(out / step["linear_image"])
    want = (20000 / 65535) ** 1.8 * 65535
    assert np.allclose(pixels, want, atol=2), (pixels[0, 0], want)


def test_a_raw_converter_s_linear_tiff_with_the_camera_s_exif_srgb_is_kept_linear(
    tmp_path, monkeypatch
):
    """dcraw/LibRaw ``-4 -T -o 0`` output with the camera's Exif ColorSpace 1 copied in and
    no ICC profile (colour_files.raw_converter_tiff): recorded as stored, and the run says it
    took them as linear and how to have them read as sRGB-encoded; its grey 20000 had been
    made 4970 by the sRGB curve, unsaid."""
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0, tiffs=True)
    raw_converter_tiff(tmp_path / "dcraw.tif", np.full((32, 32, 3), 20000, np.uint16))
    files = [(f"IMG_{k:04d}.tif", (tmp_path / "dcraw.tif").read_bytes()) for k in (1, 2)]
    out = tmp_path / "s"
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, out)
    assert r.exit_code == 0 and "Traceback" not in said and not lit_at_end, said
    step = json.loads((out / "manifest.json").read_text())["steps"][0]
    assert step["file_colour"]["said_by"] == "its Exif ColorSpace 1 (sRGB)", step
    assert "curve_undone" not in step["file_colour"], step
    assert (tifffile.imread(out / step["linear_image"]) == 20000).all()
    assert "say sRGB only by their Exif ColorSpace 1 (no ICC profile)" in said, said
    assert "taken as linear, no curve undone" in said, said


def test_an_8_bit_tiff_whose_profile_says_linear_is_recorded_linear(tmp_path, monkeypatch):
    """An 8-bit TIFF with a gamma-1.0 ICC profile, on the example's default
    ``eight_bit_response = "refuse"``: its profile says linear data, so it is recorded as
    such (grey 128 is 128 * 257); it had been refused as gamma-encoded (and with "srgb",
    read through the sRGB curve)."""
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0, tiffs=True)
    assert "eight_bit_response" not in cfg.read_text()
    buffer = io.BytesIO()
    pixels = np.full((32, 32, 3), 128, np.uint8)
    tifffile.imwrite(buffer, pixels, iccprofile=own_profile("linear"))
    files = [(f"IMG_{k:04d}.tif", buffer.getvalue()) for k in (1, 2)]
    out = tmp_path / "s"
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, out)
    assert r.exit_code == 0 and "Traceback" not in said and not lit_at_end, said
    step = json.loads((out / "manifest.json").read_text())["steps"][0]
    assert "gamma 1.0" in step["file_colour"]["curve_undone"], step
    assert (tifffile.imread(out / step["linear_image"]) == 128 * 257).all()
    # said, as fit and plan say it (the run had recorded it in the manifest only)
    assert "are 8-bit with an ICC profile whose curve is linear (gamma 1.0" in said, said
    assert "taken as linear, as the profile says, not through the sRGB curve" in said, said


def test_a_float_tiff_in_a_known_space_is_refused_by_its_pixel_type(tmp_path, monkeypatch):
    """A 32-bit float TIFF (Photoshop's, Lightroom's HDR merge) with its ProPhoto profile is
    refused as any float TIFF is, naming its pixel type: taken for conversion by its profile,
    its floats had indexed the curve's table and a Python traceback ended the run."""
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0, tiffs=True)
    buffer = io.BytesIO()
    tifffile.imwrite(
        buffer,
        np.full((32, 32, 3), 0.3, np.float32),
        photometric="rgb",
        iccprofile=icc_profile("ProPhoto RGB"),
    )
    files = [(f"IMG_{k:04d}.tif", buffer.getvalue()) for k in (1, 2)]
    out = tmp_path / "s"
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, out)
    assert r.exit_code != 0 and "Traceback" not in said and not lit_at_end, said
    assert "unsupported pixel type float32" in said, said
