"""``rti-rig plan`` from a TIFF preview whose IFD0 is a small thumbnail (NewSubfileType 1) and
whose photograph follows it (a later IFD, or a SubIFD as DNG does) plans from the photograph:
the same plan as from a TIFF of that photograph alone. The preview reader (OpenCV) had read
IFD0 and planned from a 12x8 thumbnail, with only a note that the preview was small. A TIFF of
two different full-size images is refused by name, as the replay rig and watched folder do."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tifffile
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _relief(h: int = 96, w: int = 128) -> np.ndarray:
    """A 16-bit linear RGB picture of a bumpy surface lit from the east."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    shade = 0.45 + 0.25 * np.sin(x / 7.0) * np.cos(y / 9.0) + 0.1 * np.sin(x / 3.0)
    grey = np.clip(shade, 0.05, 0.95) * 65535
    return np.stack([grey, grey * 0.9, grey * 0.8], axis=-1).astype(np.uint16)


def _plan(preview: Path, out: Path) -> tuple[str, list[str]]:
    r = runner.invoke(
        app,
        ["plan", str(preview), "--out", str(out), "--lights", "8", "--preview-light", "90,40"],
        terminal_width=400,
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "Traceback" not in said, said
    return said, out.read_text().splitlines()


@pytest.mark.parametrize("layout", ["ifd", "subifd"])
def test_plan_reads_the_photograph_of_a_thumbnail_first_tiff(tmp_path: Path, layout: str) -> None:
    pixels = _relief()
    plain = tmp_path / "plain.tif"
    tifffile.imwrite(plain, pixels, photometric="rgb")
    thumbed = tmp_path / "thumbed.tif"
    with tifffile.TiffWriter(thumbed) as tw:
        extra = {"subifds": 1} if layout == "subifd" else {}
        tw.write(pixels[::12, ::10], photometric="rgb", subfiletype=1, **extra)
        tw.write(pixels, photometric="rgb")
    with tifffile.TiffFile(thumbed) as tif:  # the file is as described
        assert tif.pages[0].shape == (8, 13, 3)
    said, lp = _plan(thumbed, tmp_path / "thumbed.lp")
    assert "the preview is only" not in said, said  # not planned from the thumbnail
    _, plain_lp = _plan(plain, tmp_path / "plain.lp")
    assert lp == plain_lp


def test_plan_refuses_a_tiff_of_two_full_size_images(tmp_path: Path) -> None:
    two = tmp_path / "two.tif"
    with tifffile.TiffWriter(two) as tw:
        tw.write(_relief(), photometric="rgb")
        tw.write(_relief()[..., 0], photometric="minisblack")
    r = runner.invoke(app, ["plan", str(two), "--out", str(tmp_path / "p.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code != 0 and "Traceback" not in said, said
    assert "two.tif" in said and "2 full-size images" in said, said
    assert "save it again as a TIFF of one image" in said, said
    assert not (tmp_path / "p.lp").exists()


def test_plan_refuses_a_tiff_of_two_pages_of_one_size(tmp_path: Path) -> None:
    """Two full-size pages of one size and type (a bracket, two frames) are one stack to
    tifffile: the preview had been handed on as a (2, H, W, 3) array and refused by its shape
    ("the preview must be an image (H, W) or (H, W, 3)"), the file and the fix unnamed."""
    two = tmp_path / "two.tif"
    with tifffile.TiffWriter(two) as tw:
        tw.write(_relief(), photometric="rgb", metadata=None)
        tw.write(_relief()[::-1], photometric="rgb", metadata=None)
    with tifffile.TiffFile(two) as tif:  # the file is as described: one series of two pages
        assert [s.shape for s in tif.series] == [(2, 96, 128, 3)]
    r = runner.invoke(
        app, ["plan", str(two), "--out", str(tmp_path / "p.lp"), "--preview-light", "90,40"]
    )
    said = " ".join(r.output.split())
    assert r.exit_code != 0 and "Traceback" not in said, said
    assert "two.tif" in said and "2 full-size images" in said, said
    assert "save it again as a TIFF of one image" in said, said
    assert not (tmp_path / "p.lp").exists()
