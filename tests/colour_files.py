"""Tiny image files that say their colour space, the bytes written here from the published
layouts (for the file-colour tests of the driver and of the CLI).

Sources: ICC.1:2001-04 (v2), 6.1 header (128 bytes: size, CMM, version, class ``mntr``,
colour space ``RGB ``, PCS ``XYZ ``, date, ``acsp``...), 6.2 tag table (count, then signature,
offset, size), 6.5.17 textDescriptionType (``desc``, reserved, ASCII count, ASCII with its
NUL, Unicode code and count, ScriptCode code, count and 67 bytes); ICC.1:2010 (v4) 10.13
multiLocalizedUnicodeType (``mluc``, reserved, record count, record size 12, then language,
country, length and offset of UTF-16BE text); ICC.1:2010 Annex B.4 (JPEG APP2: ``ICC_PROFILE``
NUL, chunk number, chunk count, data); Exif 2.3 (CIPA DC-008-2012) 4.6.5 and 4.6.3: Exif IFD
pointer 0x8769, ColorSpace 0xA001 (SHORT; 1 sRGB, 0xFFFF uncalibrated), Interoperability IFD
pointer 0xA005, InteroperabilityIndex 0x0001 (ASCII count 4; "R03" Adobe RGB, DCF 2.0).
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import cv2
import numpy as np


def icc_profile(description: str, version4: bool = False) -> bytes:
    """An RGB display profile holding only its description tag (enough for a reader of the
    description; no colour-managed viewer is asked to use it)."""
    if version4:
        text = description.encode("utf-16-be")
        body = (
            b"mluc\0\0\0\0"
            + struct.pack(">II", 1, 12)
            + b"enUS"
            + struct.pack(">II", len(text), 28)
        )
        body += text
    else:
        a = description.encode("ascii") + b"\0"
        body = b"desc\0\0\0\0" + struct.pack(">I", len(a)) + a + b"\0" * 8 + b"\0\0\0" + b"\0" * 67
    body += b"\0" * (-len(body) % 4)
    table = struct.pack(">I", 1) + struct.pack(">4sII", b"desc", 128 + 16, len(body))
    size = 128 + len(table) + len(body)
    header = (
        struct.pack(">I", size)
        + b"\0\0\0\0"
        + (bytes((4, 0x20, 0, 0)) if version4 else bytes((2, 0x10, 0, 0)))
        + b"mntrRGB XYZ "
        + b"\0" * 12
        + b"acsp"
        + b"\0" * 88
    )
    assert len(header) == 128
    return header + table + body


def exif_colour(colorspace: int, interop: bytes | None = None) -> bytes:
    """An APP1 Exif body (big-endian TIFF): IFD0 -> Exif IFD (ColorSpace, and with ``interop``
    a pointer to an Interoperability IFD holding that InteroperabilityIndex)."""
    tiff = b"MM\0*" + struct.pack(">I", 8)
    tiff += struct.pack(">H", 1) + struct.pack(">HHII", 0x8769, 4, 1, 26) + b"\0\0\0\0"
    n = 2 if interop else 1
    tiff += struct.pack(">H", n) + struct.pack(">HHIHH", 0xA001, 3, 1, colorspace, 0)
    if interop:
        tiff += struct.pack(">HHII", 0xA005, 4, 1, 26 + 2 + 12 * n + 4)
    tiff += b"\0\0\0\0"
    if interop:
        tiff += struct.pack(">H", 1) + struct.pack(">HHI4s", 0x0001, 2, 4, interop) + b"\0\0\0\0"
    return b"Exif\0\0" + tiff


def jpeg(
    level: int = 120,
    exif: bytes | None = None,
    icc: bytes | None = None,
    rgb: np.ndarray | None = None,
) -> bytes:
    """A 16x16 grey-level colour JPEG (or of the ``rgb`` pixels given, RGB order) with the
    segments given after its SOI."""
    pixels = np.full((16, 16, 3), level, np.uint8) if rgb is None else rgb[..., ::-1]
    ok, encoded = cv2.imencode(".jpg", pixels, [cv2.IMWRITE_JPEG_QUALITY, 100])
    assert ok
    data = encoded.tobytes()
    segments = b""
    if exif is not None:
        segments += b"\xff\xe1" + struct.pack(">H", len(exif) + 2) + exif
    if icc is not None:
        app2 = b"ICC_PROFILE\0" + bytes((1, 1)) + icc
        segments += b"\xff\xe2" + struct.pack(">H", len(app2) + 2) + app2
    return data[:2] + segments + data[2:]


def png(srgb: bool = False, icc: bytes | None = None) -> bytes:
    """A 16x16 colour PNG with an ``sRGB`` chunk and/or an ``iCCP`` chunk after its IHDR
    (ISO/IEC 15948, 5.3 chunk layout: length, type, data, CRC-32 of type and data; 11.3.3.3
    iCCP: profile name, NUL, compression method 0, zlib stream; 11.3.3.5 sRGB: one byte)."""
    ok, encoded = cv2.imencode(".png", np.full((16, 16, 3), 120, np.uint8))
    assert ok
    data = encoded.tobytes()

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (
            struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
        )

    extra = chunk(b"sRGB", b"\0") if srgb else b""
    if icc is not None:
        extra += chunk(b"iCCP", b"profile\0\0" + zlib.compress(icc))
    return data[:33] + extra + data[33:]  # after the signature (8) and IHDR (25)


def raw_converter_tiff(
    path: Path,
    pixels: np.ndarray,
    colorspace: int | None = 1,
    software: str = "dcraw v9.28",
    interop: bytes | None = None,
) -> None:
    """A 16-bit RGB TIFF as dcraw or LibRaw's dcraw_emu writes linear output (``-4 -T -o 0``:
    raw colour, so no ICC profile; dcraw.c ``tiff_head``: Make, Model, 300 dpi, Software, an
    Exif IFD of ExposureTime, FNumber, ISOSpeedRatings and FocalLength) after
    ``exiftool -tagsFromFile`` copied the camera's Exif ColorSpace (``colorspace``; None: not
    copied) into that IFD. ``software``: its Software tag (another writer's name: a TIFF that
    is no raw converter's); ``interop``: an Interoperability IFD holding that
    InteroperabilityIndex ("R03": Adobe RGB), pointed to from the Exif IFD.

    tifffile writes the file (it will not write tag 34665 itself: the pointer is written under
    a neighbouring code and renamed), and the Exif IFD is appended (TIFF 6.0, 2: an IFD is a
    count, 12-byte entries sorted by tag, and the next IFD's offset; a RATIONAL is two LONGs
    held beyond the IFD)."""
    import tifffile

    entries = [(33434, 5, (1, 125)), (33437, 5, (8, 1)), (34855, 3, 100), (37386, 5, (50, 1))]
    if colorspace is not None:
        entries.append((0xA001, 3, colorspace))
    tifffile.imwrite(
        path,
        pixels,
        photometric="rgb",
        software=software,
        metadata=None,
        resolution=(300, 300),
        extratags=[
            (271, "s", 0, "Canon", True),
            (272, "s", 0, "Canon EOS 5D Mark III", True),
            (34664, "I", 1, 0, True),
        ],
    )
    data = bytearray(path.read_bytes())
    assert data[:2] == b"II"
    at = len(data) + len(data) % 2
    if interop is not None:
        entries.append((0xA005, 4, 0))  # its offset: after the rationals, set below
    rationals_at = at + 2 + 12 * len(entries) + 4
    ifd, rationals = struct.pack("<H", len(entries)), b""
    interop_at = rationals_at + 8 * sum(1 for _, kind, _ in entries if kind == 5)
    for tag, kind, value in entries:
        if kind == 5:
            ifd += struct.pack("<HHII", tag, kind, 1, rationals_at + len(rationals))
            rationals += struct.pack("<II", *value)
        elif kind == 4:
            ifd += struct.pack("<HHII", tag, kind, 1, interop_at)
        else:
            ifd += struct.pack("<HHIHH", tag, kind, 1, value, 0)
    ifd += b"\0\0\0\0"
    if interop is not None:
        rationals += struct.pack("<H", 1) + struct.pack("<HHI4s", 0x0001, 2, 4, interop)
        rationals += b"\0\0\0\0"
    (first,) = struct.unpack_from("<I", data, 4)
    (count,) = struct.unpack_from("<H", data, first)
    for k in range(count):
        entry = first + 2 + 12 * k
        if struct.unpack_from("<H", data, entry)[0] == 34664:
            struct.pack_into("<HHII", data, entry, 34665, 4, 1, at)
    path.write_bytes(bytes(data + b"\0" * (at - len(data)) + ifd + rationals))
