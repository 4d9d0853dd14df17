"""``ifd_state``: whether a DNG's IFDs (IFD 0 and the SubIFDs it names, where a camera's DNG
keeps its raw image) are still unwritten zeros, and a checksum that changes as they are filled.

Why: a network share that sets a file's size first leaves zeros where a SubIFD's entries will
be; the folder watch must tell that from a damaged file before refusing it. The files here are
packed by hand from TIFF 6.0 (8-byte header; IFD = 2-byte count, 12-byte entries, 4-byte next
offset) and the DNG specification (SubIFDs 330, DNGVersion 50706).
"""

from __future__ import annotations

import struct
from pathlib import Path

from rti_rig.drivers.cameras.dng_tags import ifd_state

_SUB = 64  # where IFD 0's SubIFDs entry says the raw image's IFD lies


def _ifd(entries: list[tuple[int, int, int, bytes]]) -> bytes:
    out = struct.pack("<H", len(entries))
    for tag, kind, count, value in entries:
        out += struct.pack("<HHI", tag, kind, count) + value.ljust(4, b"\0")
    return out + struct.pack("<I", 0)


def _dng_with_subifd(sub_written: bool) -> bytes:
    ifd0 = _ifd(
        [
            (254, 4, 1, struct.pack("<I", 1)),  # IFD 0 a preview
            (330, 4, 1, struct.pack("<I", _SUB)),
            (50706, 1, 4, bytes((1, 4, 0, 0))),
        ]
    )
    data = bytearray(b"II*\0" + struct.pack("<I", 8) + ifd0)
    data += bytes(_SUB - len(data))
    sub = _ifd([(254, 4, 1, bytes(4)), (262, 3, 1, struct.pack("<H", 32803))])
    data += sub if sub_written else bytes(len(sub))
    return bytes(data)


def test_a_subifd_still_zeros_reads_as_unwritten_and_its_filling_changes_the_checksum(
    tmp_path: Path,
) -> None:
    path = tmp_path / "IMG_0001.dng"
    path.write_bytes(_dng_with_subifd(sub_written=False))
    arriving = ifd_state(path)
    path.write_bytes(_dng_with_subifd(sub_written=True))
    filled = ifd_state(path)
    assert arriving is not None and filled is not None
    assert arriving.unwritten and not filled.unwritten
    assert arriving.digest != filled.digest
    assert ifd_state(path) == filled  # the same bytes, the same state


def test_an_entry_slot_still_zeros_reads_as_unwritten(tmp_path: Path) -> None:
    data = bytearray(_dng_with_subifd(sub_written=True))
    at = _SUB + 2 + 12  # the SubIFD's second entry
    data[at : at + 12] = bytes(12)
    path = tmp_path / "IMG_0001.dng"
    path.write_bytes(bytes(data))
    state = ifd_state(path)
    assert state is not None and state.unwritten


def test_no_tiff_has_no_ifd_state(tmp_path: Path) -> None:
    path = tmp_path / "IMG_0001.dng"
    path.write_bytes(b"\0" * 64)
    assert ifd_state(path) is None
