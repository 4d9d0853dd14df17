"""A replay (`rti-rig run ACQ/dirs.lp --out S`) of files that say another colour space
converts them to linear sRGB for the session's frames: an Adobe RGB acquisition's grey is
undone by Adobe RGB's gamma 563/256 (not the sRGB curve), its green, outside sRGB, is clipped
and counted, the manifest says so, and the recorded files are kept byte for byte.

Why: a replay's 8-bit frames were undone by the sRGB curve whatever their file said, and
their Adobe RGB primaries kept under a session that fits and exports them as sRGB. Files
built in :mod:`colour_files` (sources cited there).
"""

from __future__ import annotations

import hashlib
import json
import math
import struct
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import tifffile
from colour_files import exif_colour, icc_profile, jpeg, raw_converter_tiff
from typer.testing import CliRunner

from rti_rig.cli import app


def _ring_acquisition(acq: Path, suffix: str, write: Callable[[Path, int], None]) -> Path:
    """An acquisition of eight lights on a ring at 45 degrees' elevation: image ``k`` written
    by ``write(path, k)``, listed in ``acq/dirs.lp`` (returned)."""
    acq.mkdir()
    lines = []
    for k in range(8):
        name = f"image{k + 1:02d}{suffix}"
        write(acq / name, k)
        a = 2 * math.pi * k / 8
        r = math.sqrt(0.5)
        lines.append(f"{name} {r * math.cos(a):.6f} {r * math.sin(a):.6f} {r:.6f}")
    (acq / "dirs.lp").write_text(f"{len(lines)}\n" + "\n".join(lines) + "\n")
    return acq / "dirs.lp"


def test_a_replay_of_adobe_rgb_jpegs_is_converted_to_linear_srgb(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    profile = icc_profile("Adobe RGB (1998)")

    def adobe_jpeg(path: Path, k: int) -> None:
        rgb = np.full((16, 16, 3), 60 + 10 * k, np.uint8)
        rgb[:8, :8] = (0, 200, 0)  # Adobe RGB's green: outside sRGB's gamut
        path.write_bytes(jpeg(icc=profile, rgb=rgb))

    _ring_acquisition(acq, ".jpg", adobe_jpeg)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--no-verdict"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    colour = manifest["image_colour"]
    assert colour["linear"].startswith("linear sRGB"), colour
    assert "converted from Adobe RGB (1998), said by its ICC profile" in colour["linear"]
    assert colour["jpeg"].startswith("sRGB, converted from Adobe RGB (1998)"), colour
    step = manifest["steps"][0]
    assert "gamma 563/256" in step["file_colour"]["curve_undone"], step
    clipped, of = step["file_colour"]["out_of_gamut_clipped"].split(" of ")
    assert int(clipped) >= 64 and of == "256 pixels", step  # the green square, its JPEG fringe
    with tifffile.TiffFile(out / step["linear_image"]) as tif:
        assert tif.pages[0].tags.get(34675) is not None  # linear sRGB, tagged so
        assert "converted from Adobe RGB (1998)" in tif.pages[0].description
        pixels = tif.asarray()
    source = cv2.imread(str(acq / "image01.jpg"))[..., ::-1].astype(float) / 255
    # Adobe RGB's curve, then its published RGB-to-XYZ matrix (Adobe RGB (1998) 4.3.4.1) and
    # sRGB's published XYZ-to-RGB (IEC 61966-2-1, 5.2): the sRGB curve gives ~9% more
    adobe_to_xyz = [
        [0.57667, 0.18556, 0.18823],
        [0.29734, 0.62736, 0.07529],
        [0.02703, 0.07069, 0.99134],
    ]
    xyz_to_srgb = [[3.2406, -1.5372, -0.4986], [-0.9689, 1.8758, 0.0415], [0.0557, -0.2040, 1.0570]]
    want = np.clip(
        source[12, 12] ** (563 / 256) @ np.transpose(np.dot(xyz_to_srgb, adobe_to_xyz)), 0, 1
    )
    assert np.allclose(pixels[12, 12], want * 65535, atol=12), (pixels[12, 12], want * 65535)
    assert pixels[4, 4, 0] == 0 and pixels[4, 4, 2] == 0  # the green's negatives clipped
    assert "some colours of the Adobe RGB (1998) files lie outside sRGB" in said, said
    assert "[8 of 8 images]" in said, said
    kept = sorted((out / "raw").glob("*"))[0]  # the recorded file, untouched
    assert (
        hashlib.sha256(kept.read_bytes()).digest()
        == hashlib.sha256((acq / "image01.jpg").read_bytes()).digest()
    ), kept


def test_a_replay_of_raw_converter_tiffs_with_the_camera_s_exif_srgb_keeps_them_linear(
    tmp_path: Path,
) -> None:
    """dcraw/LibRaw ``-4 -T -o 0`` TIFFs with the camera's Exif ColorSpace 1 copied in and no
    ICC profile (colour_files.raw_converter_tiff) replay as stored, and the run says it took
    them as linear; their sRGB curve had been undone (grey 20000 made 4970), unsaid."""
    acq = tmp_path / "acq"
    _ring_acquisition(
        acq,
        ".tif",
        lambda path, k: raw_converter_tiff(path, np.full((16, 16, 3), 20000 + 1000 * k, np.uint16)),
    )
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--no-verdict"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    step = json.loads((out / "manifest.json").read_text())["steps"][0]
    assert step["file_colour"]["said_by"] == "its Exif ColorSpace 1 (sRGB)", step
    linear = tifffile.imread(out / step["linear_image"])
    assert (linear == linear[0, 0, 0]).all() and linear[0, 0, 0] in range(20000, 27001, 1000)
    assert "the replayed files are 16-bit, say sRGB only by their Exif ColorSpace 1" in said
    assert "their Software tag names dcraw or LibRaw" in said, said


def _replay(tmp_path: Path, write: Callable[[Path, int], None], suffix: str) -> tuple[str, dict]:
    """``rti-rig run`` of a ring acquisition whose images ``write`` makes: its words and its
    manifest's first step (the run must succeed, with no traceback)."""
    lp = _ring_acquisition(tmp_path / "acq", suffix, write)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(lp), "--out", str(out), "--no-verdict"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    return said, json.loads((out / "manifest.json").read_text())["steps"][0] | {"out": str(out)}


def test_an_exif_srgb_tiff_no_raw_converter_wrote_has_its_curve_undone(tmp_path: Path) -> None:
    """A 16-bit TIFF that says sRGB by its Exif ColorSpace 1 alone (no ICC profile) and whose
    Software tag names no raw converter (an editor's export with its profile unticked): read
    as the tag says, its sRGB curve undone (grey 20000 is 4970 linear), and said so with how
    to have it read as linear. Every such file had been taken as linear, its mid-tones about
    2.3 times too bright. The same file written by dcraw stays linear (the test above)."""
    said, step = _replay(
        tmp_path,
        lambda path, k: raw_converter_tiff(
            path, np.full((16, 16, 3), 20000, np.uint16), software="Adobe Photoshop 25.0"
        ),
        ".tif",
    )
    assert step["file_colour"]["said_by"] == "its Exif ColorSpace 1 (sRGB)", step
    assert step["file_colour"]["written_by"] == "Adobe Photoshop 25.0", step
    linear = tifffile.imread(Path(step["out"]) / step["linear_image"])
    want = ((20000 / 65535 + 0.055) / 1.055) ** 2.4 * 65535  # IEC 61966-2-1's decoding
    assert abs(int(linear[0, 0, 0]) - want) <= 2, (linear[0, 0, 0], want)
    assert (
        "say sRGB only by their Exif ColorSpace 1 (no ICC profile): the sRGB curve undone" in said
    )
    assert "exiftool -ExifIFD:ColorSpace= FILES" in said, said


def test_a_tiff_that_says_adobe_rgb_by_its_interoperability_index_is_converted(
    tmp_path: Path,
) -> None:
    """A 16-bit TIFF whose Exif says ColorSpace 0xFFFF and InteroperabilityIndex "R03" (DCF's
    Adobe RGB, as a camera set to Adobe RGB writes it): converted from Adobe RGB as a JPEG
    saying so is. tifffile gives the Interoperability IFD as an offset, and the index had never
    been read from a TIFF: the file was called an unnamed space and left unconverted."""
    said, step = _replay(
        tmp_path,
        lambda path, k: raw_converter_tiff(
            path,
            np.full((16, 16, 3), 30000, np.uint16),
            colorspace=0xFFFF,
            software="Camera firmware 1.0",
            interop=b"R03\0",
        ),
        ".tif",
    )
    assert "InteroperabilityIndex R03" in step["file_colour"]["said_by"], step
    assert "Adobe RGB (1998)" in said, said
    assert "gamma 563/256" in step["file_colour"]["curve_undone"], step
    linear = tifffile.imread(Path(step["out"]) / step["linear_image"])
    assert abs(int(linear[0, 0, 1]) - (30000 / 65535) ** (563 / 256) * 65535) < 40, linear[0, 0]


def test_a_jpeg_whose_icc_profile_is_damaged_is_read_by_what_else_it_says(tmp_path: Path) -> None:
    """A JPEG whose ICC profile's tag table runs past its end (a count of 40, no table): the
    profile is no profile to obey, and the file's Exif ColorSpace 1 says sRGB. Parsing it had
    ended the run with a struct.error traceback."""
    damaged = icc_profile("sRGB IEC61966-2.1")[:128] + struct.pack(">I", 40)
    _, step = _replay(
        tmp_path,
        lambda path, k: path.write_bytes(jpeg(level=60 + 10 * k, icc=damaged, exif=exif_colour(1))),
        ".jpg",
    )
    assert step["file_colour"]["said_by"] == "its Exif ColorSpace 1 (sRGB)", step


def test_a_replay_of_untagged_16_bit_files_says_they_are_taken_as_linear(tmp_path: Path) -> None:
    """16-bit PNGs that say no colour space are read as linear data (a raw converter's
    output), their pixels the session's linear frames as they are; the run had said
    "assumed sRGB (the file does not say)" of them, a curve it never undid."""
    acq = tmp_path / "acq"

    def untagged_png(path: Path, k: int) -> None:
        cv2.imwrite(str(path), np.full((16, 16, 3), 9000 + 4000 * k, np.uint16))

    _ring_acquisition(acq, ".png", untagged_png)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--no-verdict"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    assert "are 16-bit and say no colour space" in said and "taken as linear data" in said, said
    assert "assumed sRGB" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    step = manifest["steps"][1]
    frame = tifffile.imread(out / step["linear_image"])
    assert (frame == 13000).all(), frame.ravel()[:3]  # as recorded: no curve undone
