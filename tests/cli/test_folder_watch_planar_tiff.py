"""A tethering program that saves each shot as a planar TIFF (PlanarConfiguration 2,
Photoshop's "Per Channel" order: all red samples, then green, then blue) into the watched
folder of the shipped folder-watch dome: ``rti-rig run`` records the shot's own RGB pixels.
The watched-folder reader had passed tifffile's samples-first (3, H, W) array on as an image
3 pixels high, where the session's other readers (fit, replay, plan) put samples last."""

from __future__ import annotations

from io import BytesIO
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import tethered_tiffs


def _planar(pixels: np.ndarray) -> bytes:
    out = BytesIO()
    stored = np.moveaxis(pixels, -1, 0)  # (3, H, W): one plane per channel
    tifffile.imwrite(out, stored, photometric="rgb", planarconfig="separate", metadata=None)
    return out.getvalue()


def test_run_records_the_rgb_pixels_of_a_planar_tiff(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(5)
    shots = [rng.integers(1000, 60000, (40, 56, 3), dtype=np.uint16) for _ in range(2)]
    files = [_planar(p) for p in shots]
    with tifffile.TiffFile(BytesIO(files[0])) as tif:  # the files are as described
        assert tif.pages[0].planarconfig == 2 and tif.pages[0].shape == (3, 40, 56)
    r, said, _tether, out, lit_at_end = tethered_tiffs(tmp_path, monkeypatch, files)
    assert r.exit_code == 0, said
    assert "Traceback" not in said, said
    for n, shot in enumerate(shots, 1):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        assert image.shape == (40, 56, 3), image.shape
        assert np.array_equal(image, shot)  # the shot's own 16-bit pixels, channels in order
    assert lit_at_end == []
