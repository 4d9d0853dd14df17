"""A RAW whose path is not UTF-8 is decoded from disk, not from a copy of the whole file in
memory, as its capture time already was (test_capture_time_not_utf8_folder.py).

rawpy cannot be given such a path (it encodes a ``str`` as UTF-8, and the name's lone
surrogates cannot be), and ``decode_raw`` had read the file's bytes whole into memory, then
copied them into a buffer for LibRaw: two copies of a 25 MB DNG beside the frame decoded from
it, for every image of a session in a folder named in Latin-1. LibRaw now reads it through
``/dev/fd/N``. Python's own allocations (tracemalloc: the file's bytes and numpy's frame) are
compared with the same decode of an ASCII-named copy; the figures are not timed here."""

from __future__ import annotations

import os
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from conftest import NOT_UTF8_NAME
from dng_spec_writer import dng

from rti_rig.drivers.cameras.raw_decode import decode_raw
from rti_rig.drivers.cameras.settings import RawDecodeSettings

pytestmark = pytest.mark.skipif(not os.path.isdir("/dev/fd"), reason="no /dev/fd here")

MOSAIC = RawDecodeSettings(mode="mosaic")  # the smallest frame: the file's copy stands out


def _peak_of_decode(path: Path) -> tuple[int, np.ndarray]:
    tracemalloc.start()
    try:
        frame = decode_raw(path, MOSAIC)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return peak, frame.pixels


def test_a_raw_in_a_folder_not_named_in_utf8_is_decoded_without_a_copy_in_memory(
    tmp_path: Path,
) -> None:
    folder = tmp_path / os.fsdecode(NOT_UTF8_NAME)
    folder.mkdir()
    mosaic = np.random.default_rng(3).integers(0, 4095, (1000, 1500), dtype=np.uint16)
    path = folder / os.fsdecode(b"caf\xe9_0001.dng")
    path.write_bytes(dng(mosaic, "RGGB", (0,) * 4, 4095))
    size = path.stat().st_size
    assert size > 2_000_000
    ascii_copy = tmp_path / "same.dng"
    ascii_copy.write_bytes(path.read_bytes())
    decode_raw(ascii_copy, MOSAIC)  # first-use allocations (imports, caches) out of the way
    baseline, expected = _peak_of_decode(ascii_copy)
    peak, pixels = _peak_of_decode(path)
    assert np.array_equal(pixels, expected)
    # the bytes read whole and their buffer had each added the file's size
    assert peak < baseline + size // 2, (peak, baseline, size)
    assert path.read_bytes() == ascii_copy.read_bytes()  # left as it was
