"""A RAW's capture time in a folder whose name is not UTF-8 is read from disk, not from a copy
of the whole file in memory.

rawpy cannot be given such a path (it encodes a ``str`` as UTF-8, and the name's lone
surrogates cannot be); its bytes had been read whole into memory at each try of the capture
time (a file still being written is tried again after each change): 25 MB a DNG, 200 ms and
49 MB of peak memory each, where LibRaw reads it from disk (``/dev/fd/N``) as any other file.
The figures are measured by a script, not here; this checks the copy is not made (Python's
own allocations, which a ``bytes`` of the file would be, stay far below its size)."""

from __future__ import annotations

import os
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from conftest import NOT_UTF8_NAME
from dng_spec_writer import dng

from rti_rig.drivers.cameras.folder_watch import capture_time

pytestmark = pytest.mark.skipif(not os.path.isdir("/dev/fd"), reason="no /dev/fd here")


def test_a_raw_in_a_folder_not_named_in_utf8_gives_its_time_without_a_copy_in_memory(
    tmp_path: Path,
) -> None:
    folder = tmp_path / os.fsdecode(NOT_UTF8_NAME)
    folder.mkdir()
    mosaic = np.random.default_rng(2).integers(0, 4095, (1000, 1500), dtype=np.uint16)
    path = folder / os.fsdecode(b"caf\xe9_0001.dng")
    path.write_bytes(dng(mosaic, "RGGB", (0,) * 4, 4095, date_time="2026:12:02 08:00:00"))
    size = path.stat().st_size
    assert size > 2_000_000
    ascii_copy = tmp_path / "same.dng"
    ascii_copy.write_bytes(path.read_bytes())
    tracemalloc.start()
    try:
        taken = capture_time(path)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert taken is not None and taken == capture_time(ascii_copy), taken
    assert peak < size // 4, (peak, size)
    assert path.read_bytes() == ascii_copy.read_bytes()  # left as it was
