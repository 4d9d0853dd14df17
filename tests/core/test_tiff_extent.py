"""One reading of a TIFF's structure serves the check before a session (``image_truncation``)
and the folder watch (``tiff_extent``): it had been written twice."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import tifffile

from rti_rig.core.image_files import image_truncation, tiff_extent


def _tiff(path: Path, pages: int = 1) -> Path:
    with tifffile.TiffWriter(path) as tw:
        for k in range(pages):
            tw.write(np.full((32, 48), 1000 * (k + 1), np.uint16), photometric="minisblack")
    return path


def test_a_whole_tiff_names_nothing_past_its_end(tmp_path: Path) -> None:
    path = _tiff(tmp_path / "a.tif")
    extent = tiff_extent(path)
    assert extent is not None and 0 < extent[1] <= path.stat().st_size
    assert image_truncation(path) is None


def test_a_tiff_cut_short_is_said_to_be_by_how_much(tmp_path: Path) -> None:
    path = _tiff(tmp_path / "a.tif")
    with tifffile.TiffFile(path) as tif:
        page = tif.pages[0]
        offset, count = int(page.dataoffsets[-1]), int(page.databytecounts[-1])
    data = path.read_bytes()
    # tifffile writes the first IFD before its data: cutting the data's end keeps it whole
    cut = tmp_path / "cut.tif"
    cut.write_bytes(data[: offset + count - 100])
    assert tiff_extent(cut, main_image=True) == (offset, offset + count)
    assert image_truncation(cut) == "its image data runs 100 bytes past its end (cut short)"


def test_the_extent_reads_every_page_unless_told_the_main_image(tmp_path: Path) -> None:
    # the image a reader takes, then a reduced-resolution thumbnail after it: the check before
    # a session (main_image) reads the image, not the thumbnail's data further on
    path = _tiff(tmp_path / "a.tif")
    with tifffile.TiffWriter(path, append=True) as tw:
        tw.write(np.full((8, 12), 7, np.uint16), photometric="minisblack", subfiletype=1)
    main, every = tiff_extent(path, main_image=True), tiff_extent(path)
    assert main is not None and every is not None and main[1] < every[1]
