"""What an image file says of its colour space: an embedded ICC profile's description, else
the Exif ColorSpace (with the Interoperability index that names Adobe RGB), else nothing.

Why: every JPEG or TIFF not from a RAW was declared sRGB, and a session's linear TIFFs were
tagged with an sRGB profile and the manifest said "linear sRGB", of an Adobe RGB JPEG or a
ProPhoto TIFF (Lightroom's default export) too. Read here, the session says what the file
said, or that the file says nothing and sRGB was assumed.

Sources: ICC.1:2001-04 (v2) and ICC.1:2010 (v4), 7.2 header (128 bytes) and 7.3 tag table,
10.5 ``desc`` (textDescriptionType: count then ASCII) and v4 10.13 ``mluc`` (records of
UTF-16BE); ICC.1:2010 Annex B.4 (a JPEG's APP2 ``ICC_PROFILE\\0``, sequence number and count,
then the chunk); Exif 2.3 (CIPA DC-008-2012) 4.6.5: ColorSpace tag 0xA001, 1 = sRGB, 0xFFFF =
uncalibrated; Interoperability IFD pointer 0xA005, InteroperabilityIndex tag 0x0001, "R98" =
sRGB (DCF basic), "R03" = Adobe RGB (DCF 2.0 option file, CIPA DC-009-2010); TIFF tag 34675
InterColorProfile (TIFF/EP, ISO 12234-2).
"""

from __future__ import annotations

import re
import struct
import zlib
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Literal

from rti_rig.drivers.cameras.exif_tags import (
    HEAD_BYTES,
    jpeg_exif_colour,
    tiff_interoperability_index,
)

Space = Literal["srgb", "adobe_rgb", "prophoto", "display_p3", "other", "untagged"]

#: the names the session gives the known spaces (their published names)
SPACE_NAMES: dict[str, str] = {
    "srgb": "sRGB",
    "adobe_rgb": "Adobe RGB (1998)",
    "prophoto": "ProPhoto RGB (ROMM RGB)",
    "display_p3": "Display P3",
}
EXIF_SRGB = 1
EXIF_UNCALIBRATED = 0xFFFF
#: what :func:`_png_colour` gives for a PNG's ``sRGB`` chunk (no Exif value: a marker only)
PNG_SRGB_CHUNK = -1


@dataclass(frozen=True)
class FileColour:
    """``space``: which one; ``name``: its name (an unknown profile's own description);
    ``said_by``: where the file says it ("" when it says nothing); ``linear_curve``: its ICC
    profile's tone curve is the identity (gamma 1.0: a linear file, as a session's own linear
    TIFFs are, whose values no curve must be undone from); ``exif_only``: only an Exif
    ColorSpace says it (no ICC profile): sRGB, its curve included, except on a raw
    converter's linear output that carries the tag copied from the camera (dcraw/LibRaw
    ``-4 -T`` writes an Exif IFD without it; ``exiftool -tagsFromFile`` adds it), told by
    ``written_by`` (:attr:`exif_linear`); ``written_by``:
    a TIFF's Software tag (305), "" where absent: what tells a linear raw converter's output
    (:attr:`exif_linear`)."""

    space: Space
    name: str
    said_by: str
    linear_curve: bool = False
    exif_only: bool = False
    written_by: str = ""

    @property
    def exif_linear(self) -> bool:
        """A 16-bit file of this colour is taken as linear though only its Exif ColorSpace
        says sRGB: its Software tag names a raw converter whose 16-bit output is linear
        (dcraw, LibRaw's dcraw_emu: ``dcraw v9.28``).

        Why not every Exif-only file: the tag declares sRGB, whose standard (IEC 61966-2-1)
        includes its curve, and the 16-bit TIFFs that carry it with no ICC profile are mostly
        gamma-encoded exports (an editor's "Save As" with its profile unticked, raw
        processors that copy the camera's tag onto their rendered output). dcraw's own TIFF
        has no ColorSpace tag and embeds a profile (gamma 1.0 for ``-4``) unless ``-o 0``
        (dcraw.c ``tiff_head``), so the tag beside dcraw's name is one copied from the camera
        (``exiftool -tagsFromFile``) onto linear data. Until 2026-12-03 every such file was
        taken as linear, an sRGB-encoded export's mid-tones fitted about 2.3 times too
        bright."""
        return self.exif_only and _LINEAR_WRITER.search(self.written_by) is not None

    def as_dict(self) -> dict[str, str]:
        said = asdict(self)
        del said["linear_curve"]  # said in the conversion's record (colour_convert)
        del said["exif_only"]  # said by said_by ("its Exif ColorSpace ...")
        if not said["written_by"]:
            del said["written_by"]
        return said


UNTAGGED = FileColour("untagged", "sRGB", "")

#: A TIFF Software tag of a raw converter whose 16-bit output is linear (dcraw.c writes
#: "dcraw v" and its version; LibRaw's dcraw_emu and unprocessed_raw the same or "LibRaw").
_LINEAR_WRITER = re.compile(r"\b(dcraw|libraw)", re.IGNORECASE)


def file_colour(path: Path) -> FileColour:
    """What ``path`` (a JPEG or a TIFF; any other file, or one that will not parse, is
    untagged) says of its colour space. An ICC profile is what colour-managed software obeys,
    so it wins over the Exif ColorSpace."""
    suffix = path.suffix.lower()
    software = ""
    try:
        if suffix in (".tif", ".tiff"):
            icc, colorspace, interop, software = _tiff_tags(path)
        elif suffix in (".jpg", ".jpeg", ".jpe"):
            with path.open("rb") as f:
                icc = jpeg_icc_profile(f.read(HEAD_BYTES))
            colorspace, interop = jpeg_exif_colour(path)
        elif suffix == ".png":
            with path.open("rb") as f:
                icc, colorspace, interop = *_png_colour(f.read(HEAD_BYTES)), None
        else:
            return UNTAGGED
    except (OSError, ValueError, struct.error, zlib.error):
        return UNTAGGED
    if colorspace == PNG_SRGB_CHUNK and not icc:
        return FileColour("srgb", "sRGB", "its PNG sRGB chunk")
    if icc:
        try:
            description, linear = icc_description(icc), icc_curve_is_linear(icc)
        except (struct.error, ValueError):
            # a damaged profile (a tag table running past its end): no profile to obey, so
            # what else the file says is read (it had ended the command with a traceback)
            description, linear = None, False
        if description:
            space = space_of_description(description)
            name = SPACE_NAMES.get(space, description)
            return FileColour(space, name, f"its ICC profile {description!r}", linear)
    if colorspace == EXIF_SRGB:
        return FileColour(
            "srgb", "sRGB", "its Exif ColorSpace 1 (sRGB)", exif_only=True, written_by=software
        )
    if colorspace == EXIF_UNCALIBRATED and interop == "R03":
        return FileColour(
            "adobe_rgb",
            SPACE_NAMES["adobe_rgb"],
            "its Exif ColorSpace 0xFFFF with InteroperabilityIndex R03 (DCF Adobe RGB)",
        )
    if colorspace == EXIF_UNCALIBRATED:
        return FileColour(
            "other",
            "an uncalibrated space (not sRGB, not named)",
            "its Exif ColorSpace 0xFFFF (uncalibrated)",
        )
    return UNTAGGED


def space_of_description(description: str) -> Space:
    """The known space an ICC profile's description names ("other" for none)."""
    d = "".join(description.lower().split())
    if "srgb" in d:
        return "srgb"
    if "adobergb" in d:
        return "adobe_rgb"
    if "prophoto" in d or "romm" in d:
        return "prophoto"
    if "displayp3" in d:
        return "display_p3"
    return "other"


def icc_tag(icc: bytes, signature: bytes) -> bytes | None:
    """The body of the tag ``signature`` in an ICC profile's tag table (ICC.1:2010 7.3: a
    count, then signature, offset and size of each tag); None if the profile has none."""
    if len(icc) < 132:
        return None
    (count,) = struct.unpack_from(">I", icc, 128)
    for i in range(min(count, 256)):
        sig, offset, size = struct.unpack_from(">4sII", icc, 132 + 12 * i)
        if sig == signature:
            return icc[offset : offset + size]
    return None


def icc_description(icc: bytes) -> str | None:
    """The profile description (tag ``desc``) of an ICC profile, v2 or v4; None if absent."""
    body = icc_tag(icc, b"desc")
    if body is None:
        return None
    if body[:4] == b"desc":
        (n,) = struct.unpack_from(">I", body, 8)
        return body[12 : 12 + n].split(b"\0")[0].decode("latin-1").strip() or None
    if body[:4] == b"mluc":
        records, record_size = struct.unpack_from(">II", body, 8)
        if records and record_size >= 12:
            length, at = struct.unpack_from(">II", body, 20)
            return body[at : at + length].decode("utf-16-be", "replace").strip() or None
    return None


def icc_curve_is_linear(icc: bytes) -> bool:
    """Whether an ICC profile's red tone curve (``rTRC``) is the identity: a ``curv`` of no
    entries or of one gamma 1.0 (u8Fixed8 0x0100), or a ``para`` of function type 0 with
    gamma 1.0 (ICC.1:2010 10.5 curveType, 10.16 parametricCurveType). A table, or no rTRC,
    is not (the named space's own curve then applies)."""
    body = icc_tag(icc, b"rTRC")
    if body is None:
        return False
    if body[:4] == b"curv" and len(body) >= 12:
        (n,) = struct.unpack_from(">I", body, 8)
        return n == 0 or (n == 1 and body[12:14] == b"\x01\x00")
    if body[:4] == b"para" and len(body) >= 16:
        kind, gamma = struct.unpack_from(">H2xi", body, 8)
        return kind == 0 and gamma == 0x10000
    return False


def jpeg_icc_profile(head: bytes) -> bytes | None:
    """The ICC profile of a JPEG's APP2 ``ICC_PROFILE`` chunks, joined in sequence order;
    None for none (or when its header segments run past ``head``)."""
    chunks: dict[int, bytes] = {}
    pos = 2
    if head[:2] != b"\xff\xd8":
        return None
    while pos + 4 <= len(head) and head[pos] == 0xFF and head[pos + 1] not in (0xDA, 0xD9):
        length = int.from_bytes(head[pos + 2 : pos + 4], "big")
        body = head[pos + 4 : pos + 2 + length]
        if head[pos + 1] == 0xE2 and body.startswith(b"ICC_PROFILE\0") and len(body) > 14:
            chunks[body[12]] = body[14:]
        pos += 2 + length
    return b"".join(chunks[k] for k in sorted(chunks)) or None


def _png_colour(head: bytes) -> tuple[bytes | None, int | None]:
    """(the ICC profile of a PNG's ``iCCP`` chunk, :data:`PNG_SRGB_CHUNK` for an ``sRGB``
    chunk) from the chunks before its image data (PNG, ISO/IEC 15948, 11.3.3.3 iCCP: a name,
    NUL, compression 0, zlib data; 11.3.3.5 sRGB)."""
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        return None, None
    icc, srgb, pos = None, None, 8
    while pos + 8 <= len(head):
        length, kind = struct.unpack_from(">I4s", head, pos)
        data = head[pos + 8 : pos + 8 + length]
        if kind == b"IDAT" or kind == b"IEND":
            break
        if kind == b"sRGB":
            srgb = PNG_SRGB_CHUNK
        elif kind == b"iCCP":
            name_end = data.index(b"\0")
            icc = zlib.decompress(data[name_end + 2 :])
        pos += 12 + length
    return icc, srgb


def _tiff_tags(path: Path) -> tuple[bytes | None, int | None, str | None, str]:
    """(InterColorProfile, Exif ColorSpace, InteroperabilityIndex, Software) of a TIFF's
    first page.

    tifffile gives the Exif IFD's InteroperabilityTag as the offset of its IFD, not its tags
    (tifffile 2026.3): that IFD is read by :func:`tiff_interoperability_index`, so a TIFF's
    "R03" (Adobe RGB) is seen as a JPEG's is (it had never been, and such a TIFF was called
    an unnamed space)."""
    import tifffile

    try:
        with tifffile.TiffFile(path) as tif:
            tags = tif.pages[0].tags
            icc_tag = tags.get(34675)
            exif_tag = tags.get(34665)
            soft_tag = tags.get(305)
            icc = bytes(icc_tag.value) if icc_tag is not None else None
            exif = exif_tag.value if exif_tag is not None else {}
            exif = exif if isinstance(exif, dict) else {}
            interop = exif.get("InteroperabilityTag")
            software = soft_tag.value if soft_tag is not None else ""
    except tifffile.TiffFileError as exc:
        raise ValueError(str(exc)) from exc
    index = (
        tiff_interoperability_index(path, interop)
        if isinstance(interop, int)
        else interop.get("InteroperabilityIndex")
        if isinstance(interop, dict)
        else None
    )
    colorspace = exif.get("ColorSpace")
    return (
        icc,
        int(colorspace) if colorspace is not None else None,
        index if isinstance(index, str) else None,
        software if isinstance(software, str) else "",
    )


def file_colour_notice(
    colour: FileColour, whose: str = "the camera's files", bits: int = 8
) -> str | None:
    """The session notice for a file that is not said to be sRGB (None for sRGB): what was
    assumed, or that the colours are another space's, recorded as such and not converted; for
    a ``bits`` 16 file said sRGB by its Exif alone, or saying nothing, that it was taken as
    linear."""
    if colour.space == "srgb":
        if colour.linear_curve and bits == 8:
            # taken as linear against the 8-bit reading a config or a reader would give: said,
            # as fit and plan say it (a run and a replay had recorded it in the manifest only)
            return (
                f"{whose} are 8-bit with an ICC profile whose curve is linear (gamma 1.0, "
                f"{colour.said_by}): taken as linear, as the profile says, not through the "
                "sRGB curve an 8-bit file is otherwise read by"
            )
        if not colour.exif_only or bits != 16:
            return None
        return exif_only_16_bit_notice(whose) if colour.exif_linear else exif_encoded_notice(whose)
    if colour.space == "untagged" and bits == 16:
        # read as linear, as every 16-bit file without a profile is (a raw converter's
        # output): it had been said "assumed sRGB", of pixels no sRGB curve was undone from
        return (
            f"{whose} are 16-bit and say no colour space (no ICC profile, no Exif "
            "ColorSpace): taken as linear data, as a raw converter writes them, no curve "
            "undone; if they are sRGB-encoded, export them with the sRGB ICC profile embedded "
            "and rti-rig undoes its curve"
        )
    if colour.space == "untagged":
        return (
            f"{whose} say no colour space (no ICC profile, no Exif ColorSpace): "
            "assumed sRGB (the file does not say); the manifest's image_colour says so"
        )
    return (
        f"{whose} are {colour.name} (said by {colour.said_by}), not sRGB: rti-rig "
        "does not convert them, so the session's images keep that space's primaries, read "
        "through the sRGB curve (8-bit) or as linear (16-bit), and carry no sRGB tag; the "
        "manifest's image_colour says so. For sRGB images, export or shoot sRGB"
    )


def exif_only_16_bit_notice(whose: str = "the camera's files") -> str:
    """The notice for 16-bit files said to be sRGB by their Exif ColorSpace 1 alone and
    written by a linear raw converter (:attr:`FileColour.exif_linear`), taken as linear.

    Why: their tag was copied from the camera onto linear data (dcraw's own TIFF has none);
    the way to the other reading is said: an embedded sRGB ICC profile, which rti-rig obeys
    as colour-managed software does."""
    return (
        f"{whose} are 16-bit, say sRGB only by their Exif ColorSpace 1 (no ICC profile) and "
        "were written by a raw converter whose 16-bit output is linear (their Software tag "
        "names dcraw or LibRaw; the tag was copied from the camera): taken as linear, no curve "
        "undone; if they are sRGB-encoded, export them with the sRGB ICC profile embedded and "
        "rti-rig undoes its curve"
    )


def exif_encoded_notice(whose: str = "the camera's files") -> str:
    """The notice for 16-bit files said to be sRGB by their Exif ColorSpace 1 alone and not
    written by a linear raw converter: their sRGB curve undone, as the tag says, and how to
    have them read as linear if they are (:attr:`FileColour.exif_linear`'s why)."""
    return (
        f"{whose} are 16-bit and say sRGB only by their Exif ColorSpace 1 (no ICC profile): "
        "the sRGB curve undone, as the tag says; if they are linear (a raw converter's output "
        "with the camera's tags copied in), remove the copied tag (exiftool "
        "-ExifIFD:ColorSpace= FILES) or embed a gamma-1.0 profile, and they are read as linear"
    )
