"""`rti-rig fit ACQ/dirs.lp` of files that say another colour space fits them in linear sRGB:
a ProPhoto 16-bit TIFF's gamma 1.8 is undone (read in place, converted a band at a time), an
Adobe RGB JPEG's gamma 563/256 (not the sRGB curve), and fit.json and the notes say so.

Why: an acquisition's 8-bit files were taken as sRGB and its 16-bit ones as linear whatever
the file said, where a session of the same files (a watched folder, a replay) converts them.
Each test fits the tagged files and, beside them, the same grey levels linearised here by the
specs' published curves (ROMM RGB, ISO 22028-2: E'^1.8; Adobe RGB (1998) 4.3.1.2: V^2.19921875)
in files that say nothing: a grey has the same primaries in every space (white stays white),
so the two fits agree only if the tagged files' curves were undone. Files built in
:mod:`colour_files` (sources cited there).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import tifffile
from colour_files import icc_profile, jpeg, raw_converter_tiff
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_colour import icc_profile as own_profile


def _directions() -> list[tuple[float, float, float]]:
    """Eight lights on two rings (30 and 60 degrees' elevation), alternating."""
    out = []
    for k in range(8):
        a, el = 2 * math.pi * k / 8, math.radians(30 + 30 * (k % 2))
        out.append((math.cos(el) * math.cos(a), math.cos(el) * math.sin(a), math.sin(el)))
    return out


def _acquisition(folder: Path, write: Callable[[Path, float], None], suffix: str) -> Path:
    """An .lp of 8 grey images, each at the level a matte flat object gives its light
    (``write(path, level)``, level in 0..1 of the encoded range)."""
    folder.mkdir()
    lines = []
    for k, d in enumerate(_directions()):
        name = f"image{k + 1:02d}{suffix}"
        write(folder / name, 0.15 + 0.6 * d[2])
        lines.append(f"{name} {d[0]:.6f} {d[1]:.6f} {d[2]:.6f}")
    (folder / "dirs.lp").write_text(f"{len(lines)}\n" + "\n".join(lines) + "\n")
    return folder / "dirs.lp"


def _fit(lp: Path, out: Path, *extra: str) -> tuple[np.ndarray, dict, str]:
    r = CliRunner().invoke(
        app,
        ["fit", str(lp), "--out", str(out), "--no-qa", "--model", "ps", *extra],
        terminal_width=400,
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    return np.load(out / "albedo.npy"), json.loads((out / "fit.json").read_text()), said


def test_a_prophoto_16_bit_tiff_acquisition_is_fitted_in_linear_srgb(tmp_path: Path) -> None:
    profile = icc_profile("ProPhoto RGB")

    def tagged(path: Path, level: float) -> None:
        pixels = np.full((16, 16, 3), round(level * 65535), np.uint16)
        tifffile.imwrite(path, pixels, iccprofile=profile)

    def linearised(path: Path, level: float) -> None:  # E' >= 1/32 here: E'^1.8
        encoded = round(level * 65535) / 65535
        tifffile.imwrite(path, np.full((16, 16, 3), round(encoded**1.8 * 65535), np.uint16))

    albedo, record, said = _fit(_acquisition(tmp_path / "a", tagged, ".tif"), tmp_path / "fa")
    want, _, _ = _fit(_acquisition(tmp_path / "b", linearised, ".tif"), tmp_path / "fb")
    assert np.allclose(albedo, want, rtol=2e-3), (albedo[8, 8], want[8, 8])
    step = record["image_colour"]["image01"]
    assert step["space"] == "prophoto" and "gamma 1.8" in step["curve_undone"], step
    assert step["out_of_gamut_clipped"] == "0 of 256 pixels", step
    assert "8 of 8 image(s) of" in said and "are ProPhoto RGB (ROMM RGB)" in said, said
    assert any("converted its primaries to linear sRGB" in n for n in record["input_notes"])


def test_an_adobe_rgb_jpeg_acquisition_is_not_read_through_the_srgb_curve(
    tmp_path: Path,
) -> None:
    profile = icc_profile("Adobe RGB (1998)")
    levels: dict[str, int] = {}

    def tagged(path: Path, level: float) -> None:
        levels[path.stem] = round(level * 120)  # dark greys: where the two curves differ most
        path.write_bytes(jpeg(level=levels[path.stem], icc=profile))

    def linearised(path: Path, level: float) -> None:
        code = levels[path.stem]
        value = round((code / 255) ** (563 / 256) * 65535)
        tifffile.imwrite(path.with_suffix(".tif"), np.full((16, 16, 3), value, np.uint16))

    albedo, record, said = _fit(_acquisition(tmp_path / "a", tagged, ".jpg"), tmp_path / "fa")
    want, _, _ = _fit(_acquisition(tmp_path / "b", linearised, ".tif"), tmp_path / "fb")
    # an 8-bit JPEG of one grey level decodes to that level within a code or so
    assert np.allclose(albedo, want, rtol=0.03), (albedo[8, 8], want[8, 8])
    step = record["image_colour"]["image01"]
    assert step["space"] == "adobe_rgb" and "563/256" in step["curve_undone"], step
    assert "are Adobe RGB (1998) (said by its ICC profile" in said, said


def test_srgb_and_untagged_files_are_read_as_before_and_said_so(tmp_path: Path) -> None:
    def untagged(path: Path, level: float) -> None:
        path.write_bytes(jpeg(level=round(level * 200)))

    _, record, said = _fit(_acquisition(tmp_path / "a", untagged, ".jpg"), tmp_path / "fa")
    step = record["image_colour"]["image01"]
    assert step["space"] == "untagged" and step["read_as"].startswith("8-bit, decoded through")
    assert "converted" not in said and not record["input_notes"], said


def test_a_converted_jpeg_is_not_called_a_16_bit_file_taken_as_linear(tmp_path: Path) -> None:
    profile = icc_profile("Adobe RGB (1998)")

    def mixed(path: Path, level: float) -> None:  # one Adobe RGB JPEG among untagged ones
        rgb = np.full((16, 16, 3), round(level * 200), np.uint8)
        tagged = path.stem == "image08"
        if tagged:
            rgb[:8, :8] = (0, 200, 0)  # Adobe RGB's green: outside sRGB's gamut
        path.write_bytes(jpeg(rgb=rgb, icc=profile if tagged else None))

    _, record, said = _fit(_acquisition(tmp_path / "a", mixed, ".jpg"), tmp_path / "fa")
    assert record["image_colour"]["image08"]["space"] == "adobe_rgb", record["image_colour"]
    assert "1 of 8 image(s) of" in said and "are Adobe RGB (1998)" in said, said
    clipped = record["image_colour"]["image08"]["out_of_gamut_clipped"].split(" of ")
    assert int(clipped[0]) >= 64 and clipped[1] == "256 pixels", clipped  # the green square
    assert "some colours of 1 of those Adobe RGB (1998) image(s) lie outside sRGB's" in said
    # converted into 16-bit linear sRGB, it is no 16-bit file whose reading is a guess
    assert "mixes" not in said, said


def test_a_raw_converter_s_linear_tiff_with_the_camera_s_exif_srgb_is_taken_as_linear(
    tmp_path: Path,
) -> None:
    """dcraw/LibRaw ``-4 -T -o 0`` output with the camera's Exif ColorSpace 1 copied in (no
    ICC profile): the tag names the camera's setting, not the file's curve, so the values are
    fitted as stored (as the same TIFFs without the tag are), and the notes say so and how to
    have the sRGB curve undone instead. Its curve had been undone: mid-tones darkened."""

    def tagged(path: Path, level: float) -> None:
        raw_converter_tiff(path, np.full((16, 16, 3), round(level * 65535), np.uint16))

    def bare(path: Path, level: float) -> None:
        raw_converter_tiff(
            path, np.full((16, 16, 3), round(level * 65535), np.uint16), colorspace=None
        )

    albedo, record, said = _fit(_acquisition(tmp_path / "a", tagged, ".tif"), tmp_path / "fa")
    want, _, _ = _fit(_acquisition(tmp_path / "b", bare, ".tif"), tmp_path / "fb")
    assert np.allclose(albedo, want, rtol=1e-4), (albedo[8, 8], want[8, 8])
    step = record["image_colour"]["image01"]
    assert step["said_by"] == "its Exif ColorSpace 1 (sRGB)", step
    assert step["read_as"].startswith("16-bit, taken as linear"), step
    assert "8 of 8 image(s) of" in said and "say sRGB only by their Exif ColorSpace 1" in said
    assert "with the sRGB ICC profile embedded" in said, said


def test_an_8_bit_tiff_whose_profile_says_linear_is_fitted_as_linear(tmp_path: Path) -> None:
    """An 8-bit TIFF whose ICC profile's curve is gamma 1.0 (rti-rig's own linear-sRGB
    profile) fits as the same values in 16-bit linear TIFFs do: the profile says linear, and
    it had been read through the sRGB curve as any 8-bit file."""

    def tagged(path: Path, level: float) -> None:
        pixels = np.full((16, 16, 3), round(level * 255), np.uint8)
        tifffile.imwrite(path, pixels, iccprofile=own_profile("linear"))

    def sixteen(path: Path, level: float) -> None:
        tifffile.imwrite(path, np.full((16, 16, 3), round(level * 255) * 257, np.uint16))

    albedo, record, said = _fit(_acquisition(tmp_path / "a", tagged, ".tif"), tmp_path / "fa")
    want, _, _ = _fit(_acquisition(tmp_path / "b", sixteen, ".tif"), tmp_path / "fb")
    assert np.allclose(albedo, want, rtol=1e-4), (albedo[8, 8], want[8, 8])
    assert "gamma 1.0" in record["image_colour"]["image01"]["curve_undone"], record
    assert "took their values as linear, as its curve (gamma 1.0) says" in said, said
    # sRGB's primaries are kept: no conversion is claimed that was never made
    assert "converted its primaries" not in said and "primaries kept" in said, said


def test_each_file_s_colour_is_read_once_and_its_clipped_pixels_counted(
    tmp_path: Path, monkeypatch
) -> None:
    """Every image's colour space is read from its file once, converted or not (an image read
    as before had been read twice), and the note counts the converted images with clipped
    pixels from the conversion's own count (it had parsed fit.json's words back)."""
    import rti_rig.app.usecases.fit as fit
    from rti_rig.drivers.cameras.file_colour import FileColour, file_colour

    reads: list[str] = []

    def counted(path: Path) -> FileColour:
        reads.append(Path(path).name)
        return file_colour(path)

    monkeypatch.setattr(fit, "file_colour", counted)
    profile = icc_profile("Adobe RGB (1998)")

    def mixed(path: Path, level: float) -> None:  # two Adobe RGB JPEGs with green, six plain
        rgb = np.full((16, 16, 3), round(level * 200), np.uint8)
        tagged = path.stem in ("image07", "image08")
        if tagged:
            rgb[:4, :4] = (0, 200, 0)  # Adobe RGB's green: outside sRGB's gamut
        path.write_bytes(jpeg(rgb=rgb, icc=profile if tagged else None))

    _, _, said = _fit(_acquisition(tmp_path / "a", mixed, ".jpg"), tmp_path / "fa")
    assert sorted(reads) == [f"image{k:02d}.jpg" for k in range(1, 9)], reads
    assert "some colours of 2 of those Adobe RGB (1998) image(s) lie outside sRGB's" in said


@pytest.mark.parametrize("suffix", [".tif", ".jpg"])
def test_the_dask_fit_converts_as_the_plain_fit_does(tmp_path: Path, suffix: str) -> None:
    """``--scheduler threads`` reads its bands through the lazy stack's own reader
    (fit.read_image, in Dask's local threads), not the plain fit's: a ProPhoto TIFF (read in
    place by rows) and an Adobe RGB JPEG (decoded) with out-of-gamut green are converted there
    too, to the same albedo bytes as the plain fit's."""
    space = "ProPhoto RGB" if suffix == ".tif" else "Adobe RGB (1998)"

    def tagged(path: Path, level: float) -> None:
        if suffix == ".tif":
            pixels = np.full((16, 16, 3), round(level * 65535), np.uint16)
            pixels[:4, :4] = (0, 65535, 0)
            tifffile.imwrite(path, pixels, iccprofile=icc_profile(space))
        else:
            rgb = np.full((16, 16, 3), round(level * 200), np.uint8)
            rgb[:4, :4] = (0, 200, 0)
            path.write_bytes(jpeg(rgb=rgb, icc=icc_profile(space)))

    lp = _acquisition(tmp_path / "a", tagged, suffix)
    plain, _, _ = _fit(lp, tmp_path / "plain")
    threads, record, said = _fit(lp, tmp_path / "threads", "--scheduler", "threads")
    assert plain.tobytes() == threads.tobytes(), (plain[8, 8], threads[8, 8])
    assert record["image_colour"]["image01"]["space"] != "untagged", record["image_colour"]
    assert "converted its primaries to linear sRGB" in said, said
