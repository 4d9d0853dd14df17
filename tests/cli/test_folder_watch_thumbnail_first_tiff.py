"""A tethering program or camera that saves each shot as a TIFF whose IFD0 is a small thumbnail
(NewSubfileType 1) and whose full image follows it (a later IFD, or a SubIFD as DNG does),
into the watched folder of the shipped folder-watch dome: ``rti-rig run`` records the full
image. The watched-folder reader had taken IFD0, so a 64x64 shot went into the session as its
16x16 thumbnail without a word. A TIFF of two different full-size images is refused as what it
is (whole, one image per file wanted), not as a damaged or half-written file."""

from __future__ import annotations

import threading
from io import BytesIO
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import folder_watch_config, refused_and_waited, tethered_run, tethered_tiffs


def _thumbnail_first(pixels: np.ndarray, layout: str) -> bytes:
    out = BytesIO()
    with tifffile.TiffWriter(out) as tw:
        extra = {"subifds": 1} if layout == "subifd" else {}
        tw.write(pixels[::4, ::4], photometric="rgb", subfiletype=1, metadata=None, **extra)
        tw.write(pixels, photometric="rgb", metadata=None)
    return out.getvalue()


@pytest.mark.parametrize("layout", ["ifd", "subifd"])
def test_run_records_the_full_image_of_a_thumbnail_first_tiff(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, layout: str
) -> None:
    rng = np.random.default_rng(3)
    shots = [rng.integers(1000, 60000, (64, 64, 3), dtype=np.uint16) for _ in range(2)]
    files = [_thumbnail_first(p, layout) for p in shots]
    with tifffile.TiffFile(BytesIO(files[0])) as tif:  # the files are as described
        assert tif.pages[0].shape == (16, 16, 3)
    r, said, _tether, out, lit_at_end = tethered_tiffs(tmp_path, monkeypatch, files)
    assert r.exit_code == 0, said
    for n, shot in enumerate(shots, 1):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        assert image.shape == (64, 64, 3), image.shape
        assert np.array_equal(image, shot)  # the shot's own 16-bit pixels, linear as saved
    assert lit_at_end == []


@pytest.mark.parametrize("pages", ["different", "of one size and type"])
def test_run_refuses_a_tiff_of_two_full_size_images_as_such(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, pages: str
) -> None:
    """Pages of one size and type are one stack to tifffile: such a file had gone on as a
    (2, 64, 64, 3) array and stopped the run as "expected an H×W or H×W×3 image"."""
    rng = np.random.default_rng(4)
    two = BytesIO()
    with tifffile.TiffWriter(two) as tw:  # two photographs, neither a thumbnail
        first = rng.integers(0, 60000, (64, 64, 3), dtype=np.uint16)
        if pages == "different":
            tw.write(first, photometric="rgb")
            tw.write(rng.integers(0, 60000, (64, 64), dtype=np.uint16), photometric="minisblack")
        else:  # as a program of its own writes them: no tifffile shape metadata
            tw.write(first, photometric="rgb", metadata=None)
            tw.write(first[::-1], photometric="rgb", metadata=None)
    if pages != "different":
        with tifffile.TiffFile(BytesIO(two.getvalue())) as tif:  # one series of two pages
            assert [s.shape for s in tif.series] == [(2, 64, 64, 3)]
    r, said, tether, out, lit_at_end = tethered_tiffs(tmp_path, monkeypatch, [two.getvalue()] * 2)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert "IMG_0001.tif" in said and "2 full-size images" in said, said
    assert "save one image per TIFF" in said and "waiting will not help" in said, said
    assert "damaged" not in said and "complete TIFF" not in said, said
    assert f"left in {tether}" in said, said
    assert not list((out / "linear").glob("image_*.tif")), said
    assert lit_at_end == []


def _thumbnail_written_alone(whole: bytes) -> bytes:
    """What a libtiff writer has saved of a thumbnail-first TIFF when it pauses within the
    full image: the thumbnail's IFD0 done, its next-IFD link still 0 (libtiff sets it only
    when it writes the next IFD), and part of the full image's strips after it. As it stands
    it is a valid TIFF of the thumbnail alone."""
    with tifffile.TiffFile(BytesIO(whole)) as tif:
        ifd0, ifd1 = tif.pages[0].offset, tif.pages[1].offset
    entries = int.from_bytes(whole[ifd0 : ifd0 + 2], "little")
    link = ifd0 + 2 + 12 * entries
    assert int.from_bytes(whole[link : link + 4], "little") == ifd1
    cut = ifd1 + (len(whole) - ifd1) // 2
    return whole[:link] + bytes(4) + whole[link + 4 : cut]


class PausedThumbnailFirst(threading.Thread):
    """A tethering program on a slow share saving thumbnail-first TIFFs, fired by the board:
    the first pulse's file comes as far as the thumbnail and part of the full image, and the
    rest only once the camera has read that part and waits for more (until the run ends
    otherwise); each later light's file comes whole."""

    def __init__(self, firmware, folder: Path, files: list[bytes], tried: threading.Event) -> None:  # type: ignore[no-untyped-def]
        super().__init__(daemon=True)
        self.firmware, self.folder, self.files, self.tried = firmware, folder, files, tried
        self.stop = threading.Event()

    def run(self) -> None:
        saved = 0
        while not self.stop.is_set():
            pulses = sum(e.what == "shutter" for e in list(self.firmware.history))
            if pulses > saved and saved < len(self.files):
                saved += 1
                target = self.folder / f"IMG_{saved:04d}.tif"
                if saved == 1:
                    target.write_bytes(_thumbnail_written_alone(self.files[0]))
                    while not self.tried.wait(0.05):
                        if self.stop.is_set():
                            return
                target.write_bytes(self.files[saved - 1])
            self.stop.wait(0.02)


def test_run_waits_for_the_full_image_of_a_thumbnail_first_tiff_paused_after_its_thumbnail(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A file that holds only a reduced-resolution image is no shot yet: it had been read as
    the thumbnail it is so far, and a 64x64 shot went into the session at 16x16 (its next
    light's whole file then refused as another size)."""
    rng = np.random.default_rng(5)
    shots = [rng.integers(1000, 60000, (64, 64, 3), dtype=np.uint16) for _ in range(2)]
    files = [_thumbnail_first(p, "ifd") for p in shots]
    with tifffile.TiffFile(BytesIO(_thumbnail_written_alone(files[0]))) as tif:
        assert [p.shape for p in tif.pages] == [(16, 16, 3)]  # the thumbnail alone, so far
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=20.0, tiffs=True)
    out = tmp_path / "s"
    # set once the part read was refused and is waited for: the copy may go on
    tried = refused_and_waited(monkeypatch)
    r, said, lit_at_end = tethered_run(
        monkeypatch,
        cfg,
        tether,
        [],
        out,
        camera=lambda firmware: PausedThumbnailFirst(firmware, tether, files, tried),
    )
    assert r.exit_code == 0, said
    assert tried.is_set(), said
    for n, shot in enumerate(shots, 1):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        assert np.array_equal(image, shot), image.shape
    assert lit_at_end == []


def test_run_refuses_a_tiff_of_a_thumbnail_alone_once_it_stays_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A whole TIFF whose only image is marked reduced-resolution is no shot: waited for (a
    writer may be on its way to the full image), then refused saying what it holds, never
    recorded at thumbnail size nor called damaged."""
    rng = np.random.default_rng(6)
    alone = BytesIO()
    tifffile.imwrite(
        alone, rng.integers(0, 60000, (16, 16, 3), dtype=np.uint16), subfiletype=1, metadata=None
    )
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=3.0, tiffs=True)
    out = tmp_path / "s"
    named = [(f"IMG_{n:04d}.tif", alone.getvalue()) for n in (1, 2)]
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, named, out)
    assert r.exit_code != 0, said
    assert "Traceback" not in said and "damaged" not in said, said
    assert "IMG_0001.tif" in said and "only a reduced-resolution image" in said, said
    assert "save the full-size image" in said and "did not change within 3 s" in said, said
    assert not list((out / "linear").glob("image_*.tif")), said
    assert lit_at_end == []
