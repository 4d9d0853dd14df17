"""How a session's images say what colour they are: an sRGB JPEG's Exif ColorSpace and ICC
profile, a linear TIFF's ICC profile and description.

Why: untagged, a colour-managed viewer takes a JPEG as sRGB only by guess and a 16-bit TIFF as
sRGB-encoded too, so the linear TIFFs showed dark; an image in camera RGB (a RAW with no colour
matrix) must carry no sRGB tag at all, so that no tool is told a colour it does not have.

The ICC profiles are built here from the published numbers (IEC 61966-2-1 sRGB primaries and
curve, adapted to the ICC's D50 with the Bradford transform, as the ICC's own sRGB profiles
are): no profile file is shipped, so there is no third-party licence to carry.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Mapping
from typing import Any, Literal

#: the sRGB primaries adapted to D50 (Bradford), in the s15Fixed16 values the ICC's and
#: LittleCMS's sRGB profiles hold; their sum is the D50 white
_SRGB_D50_PRIMARIES = (
    (0.436066, 0.222488, 0.013916),
    (0.385147, 0.716873, 0.097076),
    (0.143066, 0.060608, 0.714096),
)
_D50 = (0.9642, 1.0, 0.8249)
#: entries of the sRGB curve's table in the profile (v2 profiles have no parametric curve)
_CURVE_POINTS = 1024
#: the Exif ColorSpace value for sRGB (Exif 2.3, tag 0xA001); 0xFFFF is "uncalibrated"
EXIF_COLORSPACE_SRGB = 1

#: what a session's 16-bit linear TIFF holds, said at the head of its ImageDescription after
#: "rti-rig: " (kept as the RAW-derived description always began: "rti-rig: linear ...")
LINEAR_SRGB = "linear sRGB (IEC 61966-2-1 primaries, D65 white, gamma 1.0: NOT sRGB-encoded)"
LINEAR_CAMERA_RGB = "linear camera RGB (no colour matrix: neither sRGB primaries nor curve)"
#: what a grey (one-channel) linear TIFF not from a RAW holds: no primaries to name
LINEAR_GREY = "linear grey (one channel, gamma 1.0: NOT sRGB-encoded)"


def _s15f16(v: float) -> bytes:
    return struct.pack(">i", round(v * 65536))


def _xyz(v: tuple[float, float, float]) -> bytes:
    return b"XYZ \0\0\0\0" + b"".join(_s15f16(c) for c in v)


def _desc(text: str) -> bytes:
    """A v2 textDescriptionType: the ASCII text, no Unicode or ScriptCode text."""
    a = text.encode("ascii") + b"\0"
    return b"desc\0\0\0\0" + struct.pack(">I", len(a)) + a + b"\0" * 8 + b"\0\0\0" + b"\0" * 67


def _text(text: str) -> bytes:
    return b"text\0\0\0\0" + text.encode("ascii") + b"\0"


def _srgb_curve_table() -> bytes:
    out = []
    for i in range(_CURVE_POINTS):
        v = i / (_CURVE_POINTS - 1)
        lin = v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4
        out.append(round(lin * 65535))
    return b"curv\0\0\0\0" + struct.pack(f">I{_CURVE_POINTS}H", _CURVE_POINTS, *out)


@functools.lru_cache(maxsize=2)
def icc_profile(curve: Literal["srgb", "linear"]) -> bytes:
    """An ICC v2.1 RGB display profile with the sRGB primaries and D65 white (adapted to D50)
    and either the sRGB curve (for the 8-bit JPEGs) or a linear one (gamma 1.0, for the
    16-bit TIFFs): the profile colour-managed viewers and RTI tools read to show a file right."""
    if curve == "srgb":
        trc, name = _srgb_curve_table(), "sRGB IEC61966-2.1 (rti-rig)"
    else:
        trc, name = b"curv\0\0\0\0" + struct.pack(">IH", 1, 0x0100), "Linear sRGB (rti-rig)"
    tags: list[tuple[bytes, bytes]] = [
        (b"desc", _desc(name)),
        (b"cprt", _text("No copyright, use freely (CC0)")),
        (b"wtpt", _xyz(_D50)),
        (b"rXYZ", _xyz(_SRGB_D50_PRIMARIES[0])),
        (b"gXYZ", _xyz(_SRGB_D50_PRIMARIES[1])),
        (b"bXYZ", _xyz(_SRGB_D50_PRIMARIES[2])),
        (b"rTRC", trc),
    ]
    table_len = 4 + 12 * (len(tags) + 2)  # gTRC and bTRC share rTRC's data
    offset = 128 + table_len
    entries, data = [], b""
    for sig, body in tags:
        entries.append(struct.pack(">4sII", sig, offset + len(data), len(body)))
        if sig == b"rTRC":
            trc_at = offset + len(data)
        data += body + b"\0" * (-len(body) % 4)
    entries += [struct.pack(">4sII", s, trc_at, len(trc)) for s in (b"gTRC", b"bTRC")]
    table = struct.pack(">I", len(entries)) + b"".join(entries)
    size = 128 + len(table) + len(data)
    header = (
        struct.pack(">I", size)
        + b"\0\0\0\0"  # preferred CMM: none
        + bytes((2, 0x10, 0, 0))  # version 2.1
        + b"mntrRGB XYZ "
        + struct.pack(">6H", 2026, 1, 1, 0, 0, 0)  # fixed: the same bytes in every file
        + b"acsp"
        + b"\0" * 24  # platform, flags, manufacturer, model, attributes
        + struct.pack(">I", 0)  # rendering intent: perceptual
        + b"".join(_s15f16(c) for c in _D50)  # the PCS illuminant
        + b"rtir"  # creator
        + b"\0" * 44  # profile ID (v4 only) and reserved
    )
    assert len(header) == 128
    return header + table + data


@functools.lru_cache(maxsize=1)
def srgb_jpeg_segments() -> bytes:
    """The segments that mark a JPEG as sRGB: APP1 Exif with ColorSpace = 1 (and the Exif
    version it requires), then APP2 ICC_PROFILE with the sRGB profile (one chunk)."""
    # big-endian TIFF structure: IFD0 (one entry, the Exif IFD's offset), then the Exif IFD
    ifd0 = struct.pack(">H", 1) + struct.pack(">HHII", 0x8769, 4, 1, 26) + b"\0\0\0\0"
    exif_ifd = (
        struct.pack(">H", 2)
        + struct.pack(">HHI4s", 0x9000, 7, 4, b"0230")  # ExifVersion 2.3
        + struct.pack(">HHIHH", 0xA001, 3, 1, EXIF_COLORSPACE_SRGB, 0)  # ColorSpace
        + b"\0\0\0\0"
    )
    exif = b"Exif\0\0" + b"MM\0*" + struct.pack(">I", 8) + ifd0 + exif_ifd
    icc = b"ICC_PROFILE\0" + bytes((1, 1)) + icc_profile("srgb")
    return _segment(0xE1, exif) + _segment(0xE2, icc)


def _segment(marker: int, body: bytes) -> bytes:
    return bytes((0xFF, marker)) + struct.pack(">H", len(body) + 2) + body


def tag_jpeg_srgb(jpeg: bytes) -> bytes:
    """``jpeg`` with :func:`srgb_jpeg_segments` after its JFIF APP0 (which must come first),
    or straight after its start-of-image marker when it has none; the compressed data is
    untouched, so the pixels are the same."""
    return b"".join(tagged_jpeg_parts(jpeg))


def tagged_jpeg_parts(jpeg: bytes) -> list[memoryview | bytes]:
    """:func:`tag_jpeg_srgb` in three parts, the JPEG's own as views, not copies (written one
    after the other: a 24 MP JPEG is copied no more to be tagged)."""
    at = 2
    if jpeg[2:4] == b"\xff\xe0" and jpeg[6:11] == b"JFIF\0":
        at = 4 + int.from_bytes(jpeg[4:6], "big")
    view = memoryview(jpeg)
    return [view[:at], srgb_jpeg_segments(), view[at:]]


def jpeg_colour_tags(jpeg: bytes) -> dict[str, Any]:
    """What a JPEG's header says of its colour: ``exif_colorspace`` (the Exif ColorSpace
    value, or None) and ``icc_profile`` (the bytes of a one-chunk ICC profile, or None).
    Reads only the segments before the first scan; for checks and tests."""
    found: dict[str, Any] = {"exif_colorspace": None, "icc_profile": None}
    pos = 2
    while pos + 4 <= len(jpeg) and jpeg[pos] == 0xFF and jpeg[pos + 1] != 0xDA:
        length = int.from_bytes(jpeg[pos + 2 : pos + 4], "big")
        body = jpeg[pos + 4 : pos + 2 + length]
        if jpeg[pos + 1] == 0xE1 and body.startswith(b"Exif\0\0"):
            found["exif_colorspace"] = _exif_colorspace(body[6:])
        elif jpeg[pos + 1] == 0xE2 and body.startswith(b"ICC_PROFILE\0"):
            found["icc_profile"] = body[14:]
        pos += 2 + length
    return found


def _exif_colorspace(tiff: bytes) -> int | None:
    order = "<" if tiff[:2] == b"II" else ">"

    def entries(at: int) -> dict[int, tuple[int, int, bytes]]:
        n = struct.unpack_from(order + "H", tiff, at)[0]
        out = {}
        for i in range(n):
            tag, kind, count = struct.unpack_from(order + "HHI", tiff, at + 2 + 12 * i)
            out[tag] = (kind, count, tiff[at + 10 + 12 * i : at + 14 + 12 * i])
        return out

    ifd0 = entries(struct.unpack_from(order + "I", tiff, 4)[0])
    if 0x8769 not in ifd0:
        return None
    exif = entries(struct.unpack_from(order + "I", ifd0[0x8769][2])[0])
    if 0xA001 not in exif:
        return None
    return int(struct.unpack_from(order + "H", exif[0xA001][2])[0])


ImageColour = Literal["srgb", "camera", "mosaic"]


def decode_colour(decode: dict[str, Any]) -> ImageColour:
    """What colour a frame's pixels are in, from its ``decode`` record (empty for an image
    that was no RAW: a camera's own output, linearised from sRGB by its driver, so sRGB).

    ``"srgb"``: linear with the sRGB primaries (a RAW's colour matrix applied, or the camera's
    own sRGB); ``"camera"``: the sensor's own RGB (a RAW with no colour matrix, or
    ``output_color = "raw"``), whose JPEG is sRGB-encoded but not sRGB; ``"mosaic"``: one
    colour per pixel, not a picture."""
    if not decode:
        return "srgb"
    if decode.get("mode") == "mosaic":
        return "mosaic"
    if str(decode.get("color_space") or "").startswith("linear sRGB"):
        return "srgb"
    return "camera"


#: what the manifest's ``image_colour`` says of the JPEGs and the linear TIFFs, by colour
JPEG_COLOUR_WORDS: dict[str, str] = {
    "srgb": "sRGB (tagged: Exif ColorSpace 1 and an sRGB ICC profile; a grey image carries "
    "no colour tag)",
    "camera": "camera RGB through the sRGB curve, NOT sRGB (untagged: the RAW has no colour "
    "matrix)",
    "mosaic": "CFA mosaic through the sRGB curve: grey checkerboards, not pictures (untagged)",
}
#: (one sentence each: what the pixels are, then where the file says it; ``"grey"`` is a
#: one-channel linear TIFF not from a RAW, whose ImageDescription says linear grey)
LINEAR_COLOUR_WORDS: dict[str, str] = {
    "srgb": f"{LINEAR_SRGB}, said in the ImageDescription and tagged with a linear-sRGB ICC "
    "profile",
    "grey": f"{LINEAR_GREY}, said in the ImageDescription, with no ICC profile (no colours)",
    "camera": f"{LINEAR_CAMERA_RGB}, said in the ImageDescription, with no ICC profile",
    "mosaic": "CFA mosaic, linear, one colour per pixel, said in the ImageDescription, with no "
    "ICC profile",
}


def file_colour_kind(
    file_colour: Mapping[str, str] | None,
) -> Literal["srgb", "assumed", "other", "converted"]:
    """How a non-RAW image's colours stand by what its file said (``file_colour``: the
    ``space``, ``name`` and ``said_by`` its camera driver read; absent for a camera that writes
    no file, whose frames are linear sRGB by construction): ``"srgb"`` said so, ``"assumed"``
    the file said nothing (taken as sRGB, and said to be assumed), ``"converted"`` another
    known space converted to linear sRGB (its record's ``primaries`` says so:
    :mod:`~rti_rig.drivers.cameras.colour_convert`), ``"other"`` another space, kept as it
    is (never declared sRGB)."""
    said = file_colour or {}
    space = said.get("space")
    if space in (None, "srgb"):
        return "srgb"
    if str(said.get("primaries", "")).startswith("converted"):
        return "converted"
    return "assumed" if space == "untagged" else "other"


def converted_words(file_colour: Mapping[str, str]) -> tuple[str, str, str]:
    """(the JPEGs' words, the linear TIFFs' words, the TIFF's ImageDescription head) for
    images converted to sRGB from the space their file said: sRGB now, and from what."""
    name = file_colour.get("name", "another space")
    source = (
        f"converted from {name}, said by {file_colour.get('said_by', '')}: its curve undone "
        "and its primaries converted by the specs' matrices, colours outside sRGB clipped "
        "(each step's file_colour counts them)"
    )
    return (
        f"sRGB, {source}; tagged (Exif ColorSpace 1 and an sRGB ICC profile)",
        f"{LINEAR_SRGB}, {source}; said in the ImageDescription and tagged with a linear-sRGB "
        "ICC profile",
        f"{LINEAR_SRGB}, {source}",
    )


#: the words for a file that said nothing, of the JPEGs and of the linear TIFFs
ASSUMED_JPEG_WORDS = (
    "assumed sRGB (the file does not say): tagged sRGB (Exif ColorSpace 1 and an sRGB ICC "
    "profile) as read"
)
ASSUMED_LINEAR_WORDS = (
    f"{LINEAR_SRGB}, assumed sRGB (the file does not say), said in the ImageDescription and "
    "tagged with a linear-sRGB ICC profile"
)


def other_space_words(file_colour: Mapping[str, str]) -> tuple[str, str, str]:
    """(the JPEGs' words, the linear TIFFs' words, the TIFF's ImageDescription head) for
    images whose file said a space rti-rig does not know (another profile, Exif
    "uncalibrated"; Adobe RGB, ProPhoto and Display P3 are converted, :func:`converted_words`):
    its primaries kept, not converted, and no sRGB tag anywhere. Nor are they said to be
    linear in that space: an 8-bit file's values are undone by the sRGB curve and a 16-bit
    one's taken as stored, not by that space's own curve, which is not known."""
    name = file_colour.get("name", "another space")
    said = file_colour.get("said_by", "")
    source = f"the source file is {name}, said by {said}; not converted"
    pixels = (
        f"{name} primaries, NOT sRGB, made linear as if sRGB-encoded (8-bit) or taken as "
        f"linear as stored (16-bit), not by that space's own curve ({source})"
    )
    return (
        f"{name} primaries through the sRGB curve, NOT sRGB (untagged: {source})",
        f"{pixels}, said in the ImageDescription, with no ICC profile",
        pixels,
    )
