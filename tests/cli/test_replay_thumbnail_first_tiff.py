"""A recorded acquisition whose TIFFs open with a small thumbnail (IFD0, NewSubfileType 1) and
hold the full image in a later IFD or in a SubIFD (as some cameras and RTIBuilder exports
write them) is checked, replayed and fitted at full resolution. Every reader had taken IFD0:
`check` said "all 16x12", `run` wrote 16x12 frames of a 64x48 acquisition, `fit` fitted
thumbnails, all without a word. A TIFF with two different full-size images is refused."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tifffile
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
LIGHTS = [(0.5, 0.0), (0.0, 0.5), (-0.5, 0.0), (0.0, -0.5), (0.3, 0.3), (-0.3, 0.3)]


def _acquisition(folder: Path, layout: str) -> dict[str, np.ndarray]:
    """Six 64x48 16-bit RGB TIFFs, each a 16x12 thumbnail first and its full image after it
    (``layout``: "ifd", a second IFD; "subifd", a SubIFD of the thumbnail, as DNG does)."""
    folder.mkdir()
    rng = np.random.default_rng(7)
    full: dict[str, np.ndarray] = {}
    lines = []
    for k, (x, y) in enumerate(LIGHTS):
        pixels = rng.integers(1000, 60000, (48, 64, 3), dtype=np.uint16)
        name = f"img{k:02d}.tif"
        with tifffile.TiffWriter(folder / name) as tw:
            extra = {"subifds": 1} if layout == "subifd" else {}
            tw.write(pixels[::4, ::4], photometric="rgb", subfiletype=1, **extra)
            tw.write(pixels, photometric="rgb")
        full[name] = pixels
        lines.append(f"{name} {x} {y} {np.sqrt(1 - x * x - y * y):.6f}")
    (folder / "dirs.lp").write_text(f"{len(lines)}\n" + "\n".join(lines) + "\n")
    return full


@pytest.mark.parametrize("layout", ["ifd", "subifd"])
def test_a_thumbnail_first_acquisition_is_checked_replayed_and_fitted_full_size(
    tmp_path: Path, layout: str
) -> None:
    acq = tmp_path / "acq"
    full = _acquisition(acq, layout)
    with tifffile.TiffFile(acq / "img00.tif") as tif:  # the files are as described
        assert tif.pages[0].shape == (12, 16, 3)
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "all 64x48, all colour or all grey" in said, said

    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--lights", "6"])
    assert r.exit_code == 0, r.output
    names = {line.split()[0]: line for line in (acq / "dirs.lp").read_text().splitlines()[1:]}
    frames = sorted((out / "linear").glob("*.tif"))
    assert len(frames) == len(names)
    sources = [p for p in full.values()]
    for frame in frames:  # each frame is one source's full-resolution pixels, exactly
        pixels = tifffile.imread(frame)
        assert pixels.shape == (48, 64, 3), frame.name
        assert any(np.array_equal(pixels, src) for src in sources), frame.name

    r = runner.invoke(app, ["fit", str(acq / "dirs.lp"), "--out", str(tmp_path / "f"), "--no-qa"])
    assert r.exit_code == 0, r.output
    assert np.load(tmp_path / "f" / "normals.npy").shape[:2] == (48, 64)


def test_a_tiff_with_two_different_full_size_images_is_refused_by_name(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    _acquisition(acq, "ifd")
    rng = np.random.default_rng(1)
    with tifffile.TiffWriter(acq / "img03.tif") as tw:  # two photographs, neither a thumbnail
        tw.write(rng.integers(0, 60000, (48, 64, 3), dtype=np.uint16), photometric="rgb")
        tw.write(rng.integers(0, 250, (48, 64), dtype=np.uint8), photometric="minisblack")
    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "img03.tif" in said and "2 full-size images" in said, said
    assert "save it again as a TIFF of one image" in said, said
    assert said.endswith("RESULT: FAIL") and "Traceback" not in said
    # what it is (whole, two images), not an unreadable file to copy again from the card
    assert "whole TIFFs of more than one full-size image" in said, said
    assert "cannot be read" not in said and "copy them again" not in said, said
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(tmp_path / "s")])
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "img03.tif" in said and "2 full-size images" in said, said
    assert not (tmp_path / "s" / "linear").exists() and "Traceback" not in said
    r = runner.invoke(app, ["fit", str(acq / "dirs.lp"), "--out", str(tmp_path / "f")])
    said = " ".join(r.output.split())
    assert r.exit_code != 0 and "img03.tif" in said and "2 full-size images" in said, said
    assert "save it again as a TIFF of one image" in said and "Traceback" not in said, said
    assert "cannot be read" not in said and "copy it again" not in said, said
