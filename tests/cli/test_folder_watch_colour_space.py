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
from colour_files import exif_colour, icc_profile, jpeg
from conftest import folder_watch_config, tethered_run

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
    assert "Adobe RGB (1998) primaries, NOT sRGB" in colour["linear"], colour
    assert "assumed sRGB (the file does not say)" in colour["linear"], colour
    assert colour["linear"].index(adobe) > colour["linear"].index("Adobe RGB"), colour
    assert "Adobe RGB (1998) primaries through the sRGB curve, NOT sRGB" in colour["jpeg"]
    icc, description = _linear(out, adobe)
    assert icc is None and "Adobe RGB (1998) primaries, NOT sRGB" in description
    assert "InteroperabilityIndex R03" in description, description
    icc, description = _linear(out, bare)
    assert icc is not None and "assumed sRGB (the file does not say)" in description
    assert "the camera's files are Adobe RGB (1998)" in said, said
    assert "assumed sRGB (the file does not say)" in said, said


def test_a_prophoto_16_bit_tiff_is_not_declared_srgb(tmp_path, monkeypatch):
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=4.0, tiffs=True)
    buffer = io.BytesIO()
    # Lightroom's default TIFF export: 16-bit, its ProPhoto profile embedded
    tifffile.imwrite(
        buffer, np.full((32, 32, 3), 20000, np.uint16), iccprofile=icc_profile("ProPhoto RGB")
    )
    files = [(f"IMG_{k:04d}.tif", buffer.getvalue()) for k in (1, 2)]
    out = tmp_path / "s"
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, out)
    assert r.exit_code == 0 and "Traceback" not in said and not lit_at_end, said
    colour = json.loads((out / "manifest.json").read_text())["image_colour"]
    assert colour["linear"].startswith("ProPhoto RGB (ROMM RGB) primaries, NOT sRGB")
    assert "linear sRGB" not in colour["linear"], colour
    step = json.loads((out / "manifest.json").read_text())["steps"][0]
    icc, description = _linear(out, Path(step["image"]).stem)
    assert icc is None and "ProPhoto" in description and "sRGB (IEC" not in description
    assert "its ICC profile 'ProPhoto RGB'" in description, description
