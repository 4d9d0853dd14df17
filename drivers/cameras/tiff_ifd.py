"""A TIFF's header and IFDs, read by seeking to them in an open file (pure reads, no decoding).

Why: two modules walk TIFF structures, the folder watch's checks of a TIFF still being
written (:mod:`~rti_rig.drivers.cameras.tiff_structure`) and the DNG tags told of a file LibRaw
refused (:mod:`~rti_rig.drivers.cameras.dng_tags`); each had its own parser, and the DNG one
read the whole file into memory before each decode (48 MB of a 24-MP DNG, of which it used a
few hundred bytes). Here the header, an IFD's count and entries and a tag's values are each
read where they lie, with ``seek`` and ``read`` (never ``mmap``: a file rewritten in place by a
tethering program would end the process with SIGBUS); every read is checked against what it
got, so a file cut or shrinking meanwhile reads as "not there", never as an exception.

tifffile (a dependency) was measured on the files the tests pin and not used: it raises
``struct.error`` on a header cut short (not its own error), reads an IFD with a tag count of 0
as an image of no pixels, refuses an IFD running past the file's end without saying what of it
is there (what tells a copy cut short from garbage), and logs a warning for each damaged tag
it skips (the command line has to silence them). It reads lazily too, so it would have cost
no fewer bytes. The judging stays with the callers, which are tolerant in different ways; this
module only reads.

Source: TIFF 6.0 (header, IFD, entry layout, types 1-12), BigTIFF (version 43, 8-byte counts
and offsets, 20-byte entries, types 16-18).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import BinaryIO


@dataclass(frozen=True)
class Layout:
    """How a TIFF's structures are laid out: classic TIFF or BigTIFF, in one byte order."""

    order: str
    header: int
    #: the size of an IFD's tag count, of one entry, and of an offset (or inline value field)
    count_size: int
    entry_size: int
    offset_size: int

    @property
    def count_code(self) -> str:
        return "H" if self.count_size == 2 else "Q"

    @property
    def offset_code(self) -> str:
        return "I" if self.offset_size == 4 else "Q"

    def ifd_end(self, offset: int, count: int) -> int:
        """Where an IFD of ``count`` entries at ``offset`` ends, its next-IFD offset included."""
        return offset + self.count_size + count * self.entry_size + self.offset_size


#: a TIFF's first four bytes (byte order, version word) -> its layout
LAYOUTS = {
    b"II*\x00": Layout("<", 8, 2, 12, 4),
    b"MM\x00*": Layout(">", 8, 2, 12, 4),
    b"II+\x00": Layout("<", 16, 8, 20, 8),
    b"MM\x00+": Layout(">", 16, 8, 20, 8),
}

#: the data types a TIFF entry may have (TIFF 6.0's 1-12, IFD 13, BigTIFF's 16-18; 14 UNICODE
#: and 15 COMPLEX, which tifffile's DATATYPE and LibRaw know and some writers' private tags use)
TIFF_TYPES = frozenset({*range(1, 19)})

#: more tags than any writer uses: tifffile refuses an IFD with more as "suspicious"
MAX_TAGS = 4096

#: the unsigned integer types a value is read of: BYTE, SHORT, LONG, IFD, LONG8, IFD8
_INTEGERS = {1: ("B", 1), 3: ("H", 2), 4: ("I", 4), 13: ("I", 4), 16: ("Q", 8), 18: ("Q", 8)}


def header_size(head: bytes) -> int | None:
    """The size of the header a file beginning with ``head`` has (8 bytes, 16 for BigTIFF);
    None when ``head`` does not begin with a TIFF signature."""
    layout = LAYOUTS.get(bytes(head[:4]))
    return None if layout is None else layout.header


def read_header(f: BinaryIO) -> tuple[Layout, int] | None:
    """The layout of the TIFF open as ``f`` and the offset its header names for the first IFD;
    None when it does not begin with a TIFF signature or its header is not all there."""
    f.seek(0)
    head = f.read(16)
    layout = LAYOUTS.get(head[:4])
    if layout is None or len(head) < layout.header:
        return None
    code = layout.order + layout.offset_code
    return layout, struct.unpack_from(code, head, 4 if layout.header == 8 else 8)[0]


def read_count(f: BinaryIO, layout: Layout, offset: int) -> int | None:
    """The tag count of the IFD at ``offset`` (``f`` left just after it); None when it is not
    all in the file."""
    f.seek(offset)
    raw = f.read(layout.count_size)
    if len(raw) < layout.count_size:
        return None
    return int(struct.unpack(layout.order + layout.count_code, raw)[0])


@dataclass(frozen=True)
class Entry:
    """One IFD entry as written: its tag, data type, value count and value field (the value
    itself when it fits there, else the offset of the value)."""

    tag: int
    type: int
    count: int
    field: bytes


def read_entries(f: BinaryIO, layout: Layout, offset: int, count: int) -> list[Entry]:
    """The first ``count`` entries of the IFD at ``offset``: fewer, those wholly in the file,
    where it ends sooner."""
    f.seek(offset + layout.count_size)
    raw = f.read(count * layout.entry_size)
    head = layout.order + "HH" + layout.offset_code
    entries = []
    for n in range(len(raw) // layout.entry_size):
        at = n * layout.entry_size
        tag, kind, many = struct.unpack_from(head, raw, at)
        start = at + 4 + layout.offset_size
        entries.append(Entry(tag, kind, many, raw[start : start + layout.offset_size]))
    return entries


def read_values(
    f: BinaryIO, layout: Layout, entry: Entry, size: int, max_values: int
) -> tuple[int, ...] | None:
    """``entry``'s values when it has an unsigned integer type and at most ``max_values`` of
    them; ``()`` when they would lie past ``size`` (the file's size) or cannot all be read;
    None when its type is no integer one or its count is over ``max_values`` (damage: no value
    to read)."""
    if entry.type not in _INTEGERS or entry.count > max_values:
        return None
    code, width = _INTEGERS[entry.type]
    need = width * entry.count
    fmt = f"{layout.order}{entry.count}{code}"
    if need <= layout.offset_size:
        return struct.unpack_from(fmt, entry.field)
    (at,) = struct.unpack(layout.order + layout.offset_code, entry.field)
    if at + need > size:
        return ()
    f.seek(at)
    raw = f.read(need)
    return struct.unpack(fmt, raw) if len(raw) == need else ()
