"""A DNG writer for the tests, written from the specifications, independent of rti-rig.

Why: a decoder checked only against files written by its own project's writer can share that
writer's mistakes. This writer uses nothing of rti_rig (nor tifffile): it packs the bytes with
``struct`` following

* TIFF Revision 6.0 (Adobe, 1992): 8-byte header (byte order ``II``/``MM``, 42, offset of
  IFD0); an IFD is a 2-byte entry count, 12-byte entries sorted by tag (tag, type, count, value
  or offset; values of 4 bytes or less are stored in the entry, left-justified), then the
  4-byte offset of the next IFD (0). Types: 1 BYTE, 2 ASCII (NUL-terminated), 3 SHORT,
  4 LONG, 5 RATIONAL (two LONGs). Baseline tags 254, 256-259, 262, 271-274, 277-279, 284;
  Orientation (274): 1 = row 0 top / column 0 left, 3 = rotated 180°, 6 = row 0 is the visual
  right side (rotate 90° CW to view), 8 = row 0 is the visual left side (rotate 90° CCW).
* TIFF/EP and DNG Specification 1.4.0.0 (Adobe, 2012): PhotometricInterpretation 32803
  (CFA), CFARepeatPatternDim (33421, SHORT[2]), CFAPattern (33422, BYTE[rows×cols], 0 = red,
  1 = green, 2 = blue, row by row), ExposureTime (33434, RATIONAL), DNGVersion (50706,
  BYTE[4]), UniqueCameraModel (50708, ASCII), CFAPlaneColor (50710), CFALayout (50711, 1 =
  rectangular), BlackLevelRepeatDim (50713, SHORT[2]), BlackLevel (50714, one value per
  repeat cell, row by row), WhiteLevel (50717), ColorMatrix1 (50721, SRATIONAL[9]: XYZ →
  camera RGB, row by row), CalibrationIlluminant1 (50778, 21 = D65); type 10 SRATIONAL is two
  signed LONGs.

Licence: part of rti-rig's tests (same licence as the project). Source: the two specifications
named above; no code was copied.
"""

from __future__ import annotations

import struct
from fractions import Fraction

import numpy as np

BYTE, ASCII, SHORT, LONG, RATIONAL, SRATIONAL = 1, 2, 3, 4, 5, 10
_SIZES = {BYTE: 1, ASCII: 1, SHORT: 2, LONG: 4, RATIONAL: 8, SRATIONAL: 8}
#: CFAPattern codes (0 red, 1 green, 2 blue) of the 2×2 tile, row by row.
PATTERNS = {
    "RGGB": (0, 1, 1, 2),
    "BGGR": (2, 1, 1, 0),
    "GRBG": (1, 0, 2, 1),
    "GBRG": (1, 2, 0, 1),
}


def _pack_values(order: str, typ: int, values: list) -> bytes:  # type: ignore[type-arg]
    if typ == ASCII:
        return values[0].encode("ascii") + b"\0"
    if typ in (RATIONAL, SRATIONAL):
        code = "II" if typ == RATIONAL else "ii"
        out = b""
        for v in values:
            f = Fraction(v).limit_denominator(1_000_000)
            out += struct.pack(order + code, f.numerator, f.denominator)
        return out
    code = {BYTE: "B", SHORT: "H", LONG: "I"}[typ]
    return struct.pack(order + code * len(values), *values)


def tiff_bytes(
    entries: dict[int, tuple[int, list]],  # type: ignore[type-arg]
    pixel_data: bytes,
    big_endian: bool = False,
) -> bytes:
    """A single-IFD TIFF with one strip: ``entries`` {tag: (type, values)}; StripOffsets and
    StripByteCounts are filled in here."""
    order = ">" if big_endian else "<"
    entries = dict(entries)
    entries[273] = (LONG, [0])  # placeholder, patched below
    entries[279] = (LONG, [len(pixel_data)])
    tags = sorted(entries)
    ifd_offset = 8
    ifd_size = 2 + 12 * len(tags) + 4
    data_offset = ifd_offset + ifd_size
    blobs: dict[int, bytes] = {}
    # first pass: how large the out-of-entry values are, to place the strip after them
    for tag in tags:
        typ, values = entries[tag]
        blob = _pack_values(order, typ, values)
        if len(blob) > 4:
            blobs[tag] = blob
    extra = sum(len(b) + (len(b) & 1) for b in blobs.values())  # word-aligned (TIFF 6.0)
    strip_offset = data_offset + extra
    entries[273] = (LONG, [strip_offset])
    header = (b"MM" if big_endian else b"II") + struct.pack(order + "HI", 42, ifd_offset)
    ifd = struct.pack(order + "H", len(tags))
    tail = b""
    for tag in tags:
        typ, values = entries[tag]
        blob = _pack_values(order, typ, values)
        count = len(blob) if typ == ASCII else len(values)
        if len(blob) <= 4:
            ifd += struct.pack(order + "HHI", tag, typ, count) + blob.ljust(4, b"\0")
        else:
            ifd += struct.pack(order + "HHII", tag, typ, count, data_offset + len(tail))
            tail += blob + (b"\0" if len(blob) & 1 else b"")
    ifd += struct.pack(order + "I", 0)
    assert len(header) + len(ifd) == data_offset and data_offset + len(tail) == strip_offset
    return header + ifd + tail + pixel_data


def mosaic_from_rgb(
    rgb: np.ndarray, pattern: str, black: tuple[int, int, int, int], white: int
) -> np.ndarray:
    """Raw codes of a sensor seeing linear ``rgb`` (fractions of full scale, H×W×3): each
    photosite keeps its CFA colour, scaled between its own black level and the white level."""
    h, w, _ = rgb.shape
    codes = PATTERNS[pattern]
    out = np.empty((h, w), dtype=np.uint16)
    for k, (dy, dx) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
        v = np.clip(rgb[dy::2, dx::2, codes[k]], 0.0, 1.0)
        out[dy::2, dx::2] = np.rint(black[k] + v * (white - black[k])).astype(np.uint16)
    return out


def _one_sample_image(
    shape: tuple[int, ...], photometric: int, model: str
) -> dict[int, tuple[int, list]]:  # type: ignore[type-arg]
    """The entries every DNG here has: an uncompressed 16-bit main image (NewSubFileType 0) of
    ``shape`` (H, W), one sample per pixel in one strip, chunky, of PhotometricInterpretation
    ``photometric``, DNGVersion 1.4 and ``model`` as Model and UniqueCameraModel."""
    h, w = shape
    return {
        254: (LONG, [0]),
        256: (LONG, [w]),
        257: (LONG, [h]),
        258: (SHORT, [16]),
        259: (SHORT, [1]),
        262: (SHORT, [photometric]),
        271: (ASCII, ["SpecWriter"]),
        272: (ASCII, [model]),
        277: (SHORT, [1]),
        278: (LONG, [h]),
        284: (SHORT, [1]),
        50706: (BYTE, [1, 4, 0, 0]),
        50708: (ASCII, [model]),
    }


def dng(
    mosaic: np.ndarray,
    pattern: str = "RGGB",
    black: tuple[int, int, int, int] = (0, 0, 0, 0),
    white: int = 65535,
    orientation: int = 1,
    exposure_s: float | None = None,
    big_endian: bool = False,
    model: str = "spec-writer test camera",
    color_matrix: np.ndarray | None = None,
    date_time: str | None = None,
) -> bytes:
    """An uncompressed 16-bit CFA DNG of ``mosaic`` (raw codes, black included); ``date_time``
    is the camera clock's capture time, TIFF 6.0 DateTime (306) "YYYY:MM:DD HH:MM:SS"."""
    entries = _one_sample_image(mosaic.shape, 32803, model)  # CFA
    entries |= {
        274: (SHORT, [orientation]),
        33421: (SHORT, [2, 2]),
        33422: (BYTE, list(PATTERNS[pattern])),
        50710: (BYTE, [0, 1, 2]),
        50711: (SHORT, [1]),
        50713: (SHORT, [2, 2]),
        50714: (LONG, list(black)),
        50717: (LONG, [white]),
    }
    if exposure_s is not None:
        entries[33434] = (RATIONAL, [exposure_s])
    if date_time is not None:
        entries[306] = (ASCII, [date_time])
    if color_matrix is not None:  # ColorMatrix1 (XYZ → camera), CalibrationIlluminant1 = D65
        entries[50721] = (SRATIONAL, [float(v) for v in np.ravel(color_matrix)])
        entries[50778] = (SHORT, [21])
    data = np.ascontiguousarray(mosaic, dtype=">u2" if big_endian else "<u2").tobytes()
    return tiff_bytes(entries, data, big_endian)


def flat_dng(level: float) -> bytes:
    """A 48x32 RGGB DNG of one flat ``level`` (0-1 of a 12-bit white, no black): the shot a
    watched-folder test's camera saves, told apart from another by its level."""
    mosaic = mosaic_from_rgb(np.full((32, 48, 3), level), "RGGB", (0,) * 4, 4095)
    return dng(mosaic, "RGGB", (0,) * 4, 4095)


def monochrome_dng(grey: np.ndarray) -> bytes:
    """An uncompressed 16-bit monochrome DNG of ``grey`` (raw codes, H×W): a LinearRaw image
    (PhotometricInterpretation 34892) of one sample per pixel and no CFA tags, as a camera
    without a colour filter writes. (One spelling for the tests of its refusal, which had each
    written the entries out.)"""
    entries = _one_sample_image(grey.shape, 34892, "monochrome test camera")  # LinearRaw
    entries[50717] = (LONG, [65535])
    return tiff_bytes(entries, np.ascontiguousarray(grey, dtype="<u2").tobytes())


def srgb8(linear: np.ndarray) -> np.ndarray:
    """The sRGB 8-bit code of linear values (IEC 61966-2-1 transfer curve)."""
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    v = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    return np.rint(v * 255).astype(int)
