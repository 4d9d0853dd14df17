"""A tethering program that saves each shot as a 16-bit PNG with an alpha channel (grey +
alpha, PNG colour type 4; or RGBA, type 6) into the watched folder of the shipped
folder-watch dome. PNG alpha is never premultiplied, so ``rti-rig run`` records the grey or
colour pixels as shot and says once that the alpha was dropped. OpenCV reads grey + alpha
as four samples, the grey copied to three colours: a grey camera's PNGs had been recorded
as colour, and any PNG's alpha dropped unsaid."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
from conftest import folder_watch_config, journal, tethered_run


def _png(pixels: np.ndarray, colour_type: int) -> bytes:
    """A 16-bit PNG of ``pixels`` (H, W, samples), written to the PNG spec by hand: OpenCV
    writes no grey + alpha PNG."""
    h, w = pixels.shape[:2]
    rows = b"".join(b"\x00" + pixels[y].astype(">u2").tobytes() for y in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        crc = struct.pack(">I", zlib.crc32(kind + data))
        return struct.pack(">I", len(data)) + kind + data + crc

    head = struct.pack(">IIBBBBB", w, h, 16, colour_type, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", head)
        + chunk(b"IDAT", zlib.compress(rows))
        + chunk(b"IEND", b"")
    )


@pytest.mark.parametrize("samples", [2, 4], ids=["grey+alpha", "rgba"])
def test_run_records_the_pixels_of_a_png_with_alpha_and_says_alpha_was_dropped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, samples: int
) -> None:
    import tifffile

    rng = np.random.default_rng(11)
    shots = [rng.integers(1000, 60000, (40, 56, samples), dtype=np.uint16) for _ in range(2)]
    files = [
        (f"IMG_{n:04d}.png", _png(p, 4 if samples == 2 else 6)) for n, p in enumerate(shots, 1)
    ]
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=20.0, tiffs=True)
    cfg.write_text(cfg.read_text().replace('patterns = ["*.tif"]', 'patterns = ["*.png"]'))
    out = tmp_path / "s"
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, files, out)
    assert r.exit_code == 0, said
    assert "Traceback" not in said, said
    for n, shot in enumerate(shots, 1):
        image = tifffile.imread(out / "linear" / f"image_{n:03d}.tif")
        expected = shot[..., :3] if samples == 4 else shot[..., 0]
        assert image.shape == expected.shape, image.shape  # grey + alpha is grey
        assert np.array_equal(image, expected)  # the shot's own pixels, the alpha left out
    assert said.count("alpha channel") == 1, said  # said once, not once per image
    assert "the watched PNGs have an alpha channel" in said and "dropped" in said, said
    assert all(any("alpha" in n for n in s.get("notices", [])) for s in journal(out)), out
    assert lit_at_end == []
