"""A tethering program or camera that saves each shot as a TIFF whose IFD0 is a small thumbnail
(NewSubfileType 1) and whose full image follows it (a later IFD, or a SubIFD as DNG does),
into the watched folder of the shipped folder-watch dome: ``rti-rig run`` records the full
image. The watched-folder reader had taken IFD0, so a 64x64 shot went into the session as its
16x16 thumbnail without a word. A TIFF of two different full-size images is refused as what it
is (whole, one image per file wanted), not as a damaged or half-written file."""

from __future__ import annotations

from io import BytesIO
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import folder_watch_config, tethered_run


def _thumbnail_first(pixels: np.ndarray, layout: str) -> bytes:
    out = BytesIO()
    with tifffile.TiffWriter(out) as tw:
        extra = {"subifds": 1} if layout == "subifd" else {}
        tw.write(pixels[::4, ::4], photometric="rgb", subfiletype=1, metadata=None, **extra)
        tw.write(pixels, photometric="rgb", metadata=None)
    return out.getvalue()


def _run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, files: list[bytes]):  # type: ignore[no-untyped-def]
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=20.0, tiffs=True)
    out = tmp_path / "s"
    named = [(f"IMG_{n:04d}.tif", f) for n, f in enumerate(files, 1)]
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, named, out)
    return r, said, tether, out, lit_at_end


@pytest.mark.parametrize("layout", ["ifd", "subifd"])
def test_run_records_the_full_image_of_a_thumbnail_first_tiff(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, layout: str
) -> None:
    rng = np.random.default_rng(3)
    shots = [rng.integers(1000, 60000, (64, 64, 3), dtype=np.uint16) for _ in range(2)]
    files = [_thumbnail_first(p, layout) for p in shots]
    with tifffile.TiffFile(BytesIO(files[0])) as tif:  # the files are as described
        assert tif.pages[0].shape == (16, 16, 3)
    r, said, _tether, out, lit_at_end = _run(tmp_path, monkeypatch, files)
    assert r.exit_code == 0, said
    for n, shot in enumerate(shots, 1):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        assert image.shape == (64, 64, 3), image.shape
        assert np.array_equal(image, shot)  # the shot's own 16-bit pixels, linear as saved
    assert lit_at_end == []


def test_run_refuses_a_tiff_of_two_full_size_images_as_such(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(4)
    two = BytesIO()
    with tifffile.TiffWriter(two) as tw:  # two photographs, neither a thumbnail
        tw.write(rng.integers(0, 60000, (64, 64, 3), dtype=np.uint16), photometric="rgb")
        tw.write(rng.integers(0, 60000, (64, 64), dtype=np.uint16), photometric="minisblack")
    r, said, tether, out, lit_at_end = _run(tmp_path, monkeypatch, [two.getvalue()] * 2)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert "IMG_0001.tif" in said and "2 full-size images" in said, said
    assert "save one image per TIFF" in said and "waiting will not help" in said, said
    assert "damaged" not in said and "complete TIFF" not in said, said
    assert f"left in {tether}" in said, said
    assert not list((out / "linear").glob("image_*.tif")), said
    assert lit_at_end == []
