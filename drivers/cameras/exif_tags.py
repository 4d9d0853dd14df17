"""A JPEG's EXIF capture time (DateTimeOriginal) and Orientation, read from its APP1 segment,
and a TIFF's Orientation, with the TIFF reads of :mod:`~rti_rig.drivers.cameras.tiff_ifd`
(pure reads of the header segments and IFD0, no decoding).

Why: a watched folder of a camera's JPEGs (``eight_bit_response = "srgb"``) read no capture
time from them, so each image was said to come from a file that "holds no capture time (no EXIF
DateTimeOriginal ...)" while every camera JPEG holds one, and a late or extra JPEG was never
checked against the shutter pulses. RAWs (LibRaw) and TIFFs (tifffile) had theirs read.

Source: JPEG (ITU-T T.81, B.1.1: markers, segment lengths), JFIF/Exif 2.3 (APP1 "Exif\\0\\0"
then a TIFF whose IFD0 points at the Exif IFD, tag 0x8769; DateTimeOriginal is tag 0x9003,
ASCII "YYYY:MM:DD HH:MM:SS").
"""

from __future__ import annotations

import io
import struct
from pathlib import Path
from typing import BinaryIO

from rti_rig.drivers.cameras.tiff_ifd import (
    Entry,
    Layout,
    read_count,
    read_entries,
    read_header,
    read_values,
)

#: how much of a file's head is read for its header segments: an Exif APP1 is at most 64 KiB
#: and comes first (after a JFIF APP0 at most); a file with more before it is not searched on
HEAD_BYTES = 256 * 1024
#: markers with no length (TEM, RSTn) and those that end the header segments (SOS, EOI)
_NO_LENGTH = {0x01, *range(0xD0, 0xD8)}
_END_OF_HEADER = {0xDA, 0xD9}

EXIF_IFD_TAG = 0x8769
DATE_TIME_ORIGINAL_TAG = 0x9003
ORIENTATION_TAG = 274


def jpeg_datetime_original(path: Path) -> tuple[bool, str | None]:
    """(whether waiting cannot change the answer, the EXIF DateTimeOriginal as written).

    False while the file's head is not all written (shorter than its segments say, or zeros
    still: a network share sets the size first), so the caller waits for it as for a RAW;
    True with None for a file that is no JPEG or whose header holds no such time."""
    final, exif = _exif_tiff(path)
    return final, (_datetime_original(exif) if exif else None)


def jpeg_orientation(path: Path) -> int | None:
    """The EXIF Orientation (IFD0 tag 274) of a whole JPEG, None where it has none.

    Why: OpenCV reads a JPEG as stored (``IMREAD_UNCHANGED``), as every reader of a session
    does, so a JPEG from a camera held on its side is recorded sideways beside the upright
    picture a viewer shows of the folder's file; the RAW path said so of a rotated RAW, the
    JPEG path said nothing."""
    exif = _exif_tiff(path)[1]
    if not exif:
        return None
    f = io.BytesIO(exif)
    found = read_header(f)
    if found is None:
        return None
    layout, ifd0 = found
    entry = _entry(f, layout, ifd0, ORIENTATION_TAG)
    value = None if entry is None else read_values(f, layout, entry, len(exif), 1)
    return int(value[0]) if value else None


def tiff_orientation(path: Path) -> int | None:
    """The Orientation (IFD0 tag 274) of a TIFF, None where it has none or cannot be read.

    Why: tifffile reads a TIFF as stored, as OpenCV reads a JPEG, so a TIFF saved with its
    camera's Orientation is recorded as stored, sideways where the camera was turned."""
    try:
        with path.open("rb") as f:
            size = path.stat().st_size
            found = read_header(f)
            if found is None:
                return None
            layout, ifd0 = found
            count = read_count(f, layout, ifd0)
            if not count or count > 4096:
                return None
            entry = next(
                (e for e in read_entries(f, layout, ifd0, count) if e.tag == ORIENTATION_TAG),
                None,
            )
            value = None if entry is None else read_values(f, layout, entry, size, 1)
    except OSError:
        return None
    return int(value[0]) if value else None


def _exif_tiff(path: Path) -> tuple[bool, bytes | None]:
    """(whether waiting cannot change the answer, the TIFF of the JPEG's Exif APP1 segment or
    None)."""
    try:
        with path.open("rb") as f:
            head = f.read(HEAD_BYTES)
    except OSError:
        return False, None
    if len(head) < 4 or not any(head[:4]):
        return False, None
    if head[:2] != b"\xff\xd8":
        return True, None  # no JPEG: waiting will not make it one
    exif = _exif_segment(head)
    if exif is None:
        return len(head) >= HEAD_BYTES, None  # cut short: more may come
    return True, exif or None


def _exif_segment(head: bytes) -> bytes | None:
    """The TIFF of ``head``'s Exif APP1 segment; ``b""`` when its header segments are all
    there and hold none (or are damaged); None when they run past ``head`` (not all written)."""
    pos = 2
    while True:
        if pos + 2 > len(head):
            return None
        if head[pos] != 0xFF:
            return b""  # not a marker where one must be: damaged, never mended by waiting
        marker = head[pos + 1]
        if marker == 0xFF:  # fill byte before a marker (T.81 B.1.1.2)
            pos += 1
            continue
        if marker in _END_OF_HEADER:
            return b""
        if marker in _NO_LENGTH:
            pos += 2
            continue
        if pos + 4 > len(head):
            return None
        length = int.from_bytes(head[pos + 2 : pos + 4], "big")
        if length < 2:
            return b""
        end = pos + 2 + length
        if end > len(head):
            return None
        body = head[pos + 4 : end]
        if marker == 0xE1 and body.startswith(b"Exif\0\0"):
            return body[6:] or b""
        pos = end


def _datetime_original(tiff: bytes) -> str | None:
    """The DateTimeOriginal of an Exif TIFF (IFD0 -> Exif IFD -> 0x9003), None where absent
    or damaged."""
    f = io.BytesIO(tiff)
    found = read_header(f)
    if found is None:
        return None
    layout, ifd0 = found
    at = _entry(f, layout, ifd0, EXIF_IFD_TAG)
    if at is None:
        return None
    pointer = read_values(f, layout, at, len(tiff), 1)
    if not pointer:
        return None
    stamp = _entry(f, layout, pointer[0], DATE_TIME_ORIGINAL_TAG)
    if stamp is None or stamp.type != 2 or not 0 < stamp.count <= 64:
        return None
    if stamp.count <= layout.offset_size:
        raw = stamp.field[: stamp.count]
    else:
        (offset,) = struct.unpack(layout.order + layout.offset_code, stamp.field)
        raw = tiff[offset : offset + stamp.count]
    return raw.decode("ascii", "replace").rstrip("\x00") or None


def _entry(f: BinaryIO, layout: Layout, offset: int, tag: int) -> Entry | None:
    count = read_count(f, layout, offset)
    if not count or count > 4096:
        return None
    return next((e for e in read_entries(f, layout, offset, count) if e.tag == tag), None)


COLOR_SPACE_TAG = 0xA001
INTEROPERABILITY_IFD_TAG = 0xA005
INTEROPERABILITY_INDEX_TAG = 0x0001


def jpeg_exif_colour(path: Path) -> tuple[int | None, str | None]:
    """(the Exif ColorSpace, the InteroperabilityIndex) of a JPEG, each None where absent.

    Why: a camera set to Adobe RGB writes ColorSpace 0xFFFF ("uncalibrated") and names the
    space only by InteroperabilityIndex "R03" (Exif 2.3, 4.6.5; DCF 2.0), so both are read."""
    exif = _exif_tiff(path)[1]
    if not exif:
        return None, None
    f = io.BytesIO(exif)
    found = read_header(f)
    if found is None:
        return None, None
    layout, ifd0 = found
    at = _entry(f, layout, ifd0, EXIF_IFD_TAG)
    pointer = None if at is None else read_values(f, layout, at, len(exif), 1)
    if not pointer:
        return None, None
    space = _entry(f, layout, pointer[0], COLOR_SPACE_TAG)
    value = None if space is None else read_values(f, layout, space, len(exif), 1)
    colorspace = int(value[0]) if value else None
    interop = _entry(f, layout, pointer[0], INTEROPERABILITY_IFD_TAG)
    where = None if interop is None else read_values(f, layout, interop, len(exif), 1)
    if not where:
        return colorspace, None
    return colorspace, _interop_index(f, layout, where[0])


def tiff_interoperability_index(path: Path, offset: int) -> str | None:
    """The InteroperabilityIndex of a TIFF whose Exif IFD points its Interoperability IFD at
    ``offset``; None where that IFD or the tag is not there (or is damaged).

    Why: tifffile reads a TIFF's Exif IFD but gives its InteroperabilityTag as that offset,
    not the IFD's tags (tifffile 2026.3), so a TIFF's "R03" (Adobe RGB) had never been read;
    the IFD is read here as a JPEG's is (:func:`jpeg_exif_colour`)."""
    with path.open("rb") as f:
        found = read_header(f)
        return None if found is None else _interop_index(f, found[0], offset)


def _interop_index(f: BinaryIO, layout: Layout, offset: int) -> str | None:
    """The InteroperabilityIndex ("R98", "R03") of the Interoperability IFD at ``offset``."""
    index = _entry(f, layout, offset, INTEROPERABILITY_INDEX_TAG)
    if index is None or index.type != 2 or not 0 < index.count <= 4:
        return None
    return index.field[: index.count].decode("ascii", "replace").rstrip("\0") or None
