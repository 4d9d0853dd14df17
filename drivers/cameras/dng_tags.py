"""What a file LibRaw refused as "unsupported" says of itself, read from its own TIFF tags.

Why: LibRaw gives one error, LIBRAW_FILE_UNSUPPORTED ("Unsupported file format or not RAW
file"), both for a format it does not know (a body newer than it, a DNG compressed as JPEG XL
by a rawpy built without it) and for a DNG whose tags are damaged (its ImageWidth's tag number
lost, its PhotometricInterpretation garbage): its identify step finds no image it can read in
either. A damaged DNG had been refused with "a camera newer than this LibRaw … Update rawpy",
advice that cannot help. A DNG's own tags tell the two apart where they can: the main image's
IFD (NewSubFileType 0, in IFD 0 or one of its SubIFDs) must give a size, a sample depth, a
photometric kind a raw image has, its data's place inside the file, and a compression the DNG
specification names. Where all of that holds, nothing here can tell, and :func:`dng_refusal`
says both possibilities.

Asked of every decode (:func:`read_blind`), it reads only the header, the IFDs and the values of
the tags above, by seeking to them (:mod:`~rti_rig.drivers.cameras.tiff_ifd`, the TIFF reader
the folder watch's checks use too): it had read the whole file, 48 MB of a 24-MP DNG, per
image.

Sources: TIFF 6.0 (header, IFD entries, tags 254-279, 322-325) and the DNG Specification
1.7.1.0 (DNGVersion 50706, DNGBackwardVersion 50707, SubIFDs 330, PhotometricInterpretation
32803 CFA / 34892 LinearRaw, compressions 1, 7, 8, 34892, 52546).
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

from rti_rig.core.shell_words import pip_upgrade
from rti_rig.drivers.cameras.tiff_ifd import (
    MAX_TAGS,
    Layout,
    read_count,
    read_entries,
    read_header,
    read_values,
)

#: DNG compressions (DNG 1.7.1 §"Compression") LibRaw 0.22 decodes in any build: none,
#: lossless JPEG, Deflate, lossy JPEG
DNG_COMPRESSIONS = {1: "uncompressed", 7: "lossless JPEG", 8: "Deflate", 34892: "lossy JPEG"}
#: JPEG XL (new in DNG 1.7): named apart, as LibRaw decodes it only when built with it
JPEG_XL = 52546
#: photometric kinds of a DNG's raw image: BlackIsZero (a monochrome sensor), CFA, LinearRaw
RAW_PHOTOMETRIC = {1, 32803, 34892}
#: the DNG version LibRaw 0.22 was written for (DNG 1.7: JPEG XL only when built with it)
LIBRAW_DNG = (1, 7)
#: what lays a CFA mosaic out (TIFF/EP): without them LibRaw fills the pattern from memory
#: it never set, a different one at each read
CFA_TAGS = {33421: "CFARepeatPatternDim", 33422: "CFAPattern"}
#: values read of one integer tag at most (the most, StripOffsets of a strip per row, has a
#: sensor's rows); a larger count is damage, read as a tag given no value
_MAX_VALUES = 1 << 16
#: the tags whose values are read (any other's, a DNGPrivateData or XMP of hundreds of KB
#: among them, are never read): NewSubFileType, ImageWidth, ImageLength, BitsPerSample,
#: Compression, PhotometricInterpretation, StripOffsets, StripByteCounts, TileOffsets,
#: TileByteCounts, SubIFDs, the CFA tags, DNGVersion, DNGBackwardVersion
_READ = frozenset({254, 256, 257, 258, 259, 262, 273, 279, 324, 325, 330, *CFA_TAGS, 50706, 50707})


@dataclass
class DngTags:
    """The tags of ``path`` that matter to whether LibRaw could read it."""

    version: tuple[int, ...] | None = None
    backward: tuple[int, ...] | None = None
    #: what is wrong with its main image's IFD, as phrases ("it gives no ImageWidth")
    damage: list[str] = field(default_factory=list)
    #: why its CFA cannot be laid out (a CFA image without CFAPattern), or None
    cfa_lost: str | None = None
    #: why its picture's place in the file is not known (no StripOffsets or TileOffsets
    #: entry at all), or None
    data_lost: str | None = None
    compression: int | None = None


def _ifd(f: BinaryIO, layout: Layout, offset: int, size: int) -> dict[int, tuple[int, ...]] | None:
    """{tag: values} of the integer tags of :data:`_READ` in the IFD at ``offset``, all of it
    in the ``size`` bytes of ``f``; None where there is no such IFD. A tag whose values lie
    past the end reads as given none (``()``); one of another type or an absurd count too,
    unless an entry before it of the same tag gave values.

    An offset past the end is "no such IFD" before anything is read: a SubIFDs entry of an
    8-byte type (LONG8, IFD8) in a damaged file can name one past 2**63, which ``seek``
    refuses with a ValueError, not an OSError (it had ended the decode with that error)."""
    if offset < layout.header or offset + layout.count_size > size:
        return None
    count = read_count(f, layout, offset)
    if count is None or not 1 <= count <= MAX_TAGS or layout.ifd_end(offset, count) > size:
        return None
    entries = read_entries(f, layout, offset, count)
    if len(entries) < count:  # the file shrank while read (rewritten in place)
        return None
    tags: dict[int, tuple[int, ...]] = {}
    for entry in entries:
        if entry.tag not in _READ:
            continue
        values = read_values(f, layout, entry, size, _MAX_VALUES)
        if values is None:
            tags.setdefault(entry.tag, ())
        else:
            tags[entry.tag] = values
    return tags


def _main_image(
    f: BinaryIO, layout: Layout, size: int, first: dict[int, tuple[int, ...]]
) -> dict[int, tuple[int, ...]] | None:
    """The IFD of the full-resolution raw image: the first of IFD 0 and its SubIFDs whose
    NewSubFileType is 0 (TIFF's default when the tag is absent)."""
    candidates = [first]
    for offset in first.get(330, ()):
        sub = _ifd(f, layout, offset, size)
        if sub is not None:
            candidates.append(sub)
    for tags in candidates:
        if tags.get(254, (0,))[:1] == (0,):
            return tags
    return None


def read_dng_tags(path: Path) -> DngTags | None:
    """``path``'s DNG tags, or None when it is no classic TIFF naming a DNGVersion in IFD 0
    (another RAW format, a BigTIFF, or not a TIFF at all), or cannot be read.

    Only the header, the IFDs and the values of :data:`_READ` are read (a few hundred bytes
    of a DNG of tens of MB: this is asked of every decode), each where it lies."""
    try:
        with path.open("rb") as f:
            return _read_dng_tags(f, os.fstat(f.fileno()).st_size)
    except OSError:
        return None


def _read_dng_tags(f: BinaryIO, size: int) -> DngTags | None:
    named = read_header(f)
    if named is None or named[0].header != 8:  # not a TIFF, a BigTIFF, or a header cut
        return None
    layout, offset = named
    ifd0 = _ifd(f, layout, offset, size)
    if ifd0 is None or len(ifd0.get(50706, ())) != 4:
        return None
    found = DngTags(version=ifd0[50706], backward=ifd0.get(50707) or None)
    main = _main_image(f, layout, size, ifd0)
    if main is None:
        found.damage.append("none of its IFDs is marked as the main image (NewSubFileType 0)")
        return found
    for tag, name in ((256, "ImageWidth"), (257, "ImageLength")):
        if not main.get(tag) or main[tag][0] == 0:
            found.damage.append(f"its main image gives no {name}")
    bits = main.get(258)
    if not bits or not all(1 <= b <= 32 for b in bits):
        found.damage.append(
            f"its main image's BitsPerSample is {list(bits) if bits else 'missing'}"
        )
    photometric = main.get(262)
    if not photometric or photometric[0] not in RAW_PHOTOMETRIC:
        said = photometric[0] if photometric else "missing"
        found.damage.append(f"its main image's PhotometricInterpretation is {said}")
    if 273 not in main and 324 not in main:  # absent, not unreadable (a copy still coming)
        found.data_lost = "its main image gives no StripOffsets or TileOffsets"
    offsets, counts = main.get(273) or main.get(324), main.get(279) or main.get(325)
    if not offsets or not counts or len(offsets) != len(counts):
        found.damage.append("its main image names no data (strip or tile offsets and counts)")
    elif any(o + c > size for o, c in zip(offsets, counts, strict=True)):
        found.damage.append("its main image's data runs past the end of the file")
    if photometric and photometric[0] == 32803:
        lost = [name for tag, name in CFA_TAGS.items() if not main.get(tag)]
        if lost:
            found.cfa_lost = f"its main image, a CFA mosaic, gives no {' or '.join(lost)}"
            found.damage.append(found.cfa_lost)
    compression = main.get(259)
    found.compression = compression[0] if compression else None
    if compression is None:
        found.damage.append("its main image gives no Compression")
    return found


@dataclass(frozen=True)
class IfdState:
    """What a DNG's structure holds at one read: a checksum of its header and the bytes of
    IFD 0 and its SubIFDs, and whether any of them is still unwritten (zeros)."""

    digest: bytes
    #: an IFD its header or IFD 0 names reads as zeros (a count of 0, or an entry slot all
    #: zeros: no TIFF entry has type 0), as in a file a network share sized first
    unwritten: bool


def ifd_state(path: Path) -> IfdState | None:
    """:class:`IfdState` of ``path``, a classic TIFF (a DNG); None when it is none, or cannot
    be read.

    Why: a copy over a network share (SMB, some NAS clients) may set a file's final size first
    and fill its bytes afterwards, not always in order, so a DNG can be whole-sized with
    zeros where its IFD's CFAPattern or StripOffsets entry will be: the refusal of such a
    file (:func:`read_blind`) is only true once the bytes have stopped changing, which this
    checksum tells cheaply (a few hundred bytes read, never the picture)."""
    try:
        with path.open("rb") as f:
            return _ifd_state(f, os.fstat(f.fileno()).st_size)
    except OSError:
        return None


def _ifd_state(f: BinaryIO, size: int) -> IfdState | None:
    named = read_header(f)
    if named is None or named[0].header != 8:
        return None
    layout, first = named
    f.seek(0)
    digest = hashlib.blake2b(f.read(layout.header), digest_size=16)
    unwritten = False
    offsets, done = [first], set()
    while offsets:
        offset = offsets.pop(0)
        if offset in done or len(done) > 16:
            continue
        done.add(offset)
        digest.update(offset.to_bytes(8, "little"))
        if offset < layout.header or offset + layout.count_size > size:
            unwritten = True  # a SubIFDs value not written yet, or garbage
            continue
        count = read_count(f, layout, offset)
        if not count or count > MAX_TAGS:
            unwritten = unwritten or count == 0
            continue
        f.seek(offset)
        digest.update(f.read(layout.ifd_end(offset, count) - offset))
        for entry in read_entries(f, layout, offset, count):
            if entry.tag == 0 and entry.type == 0 and not any(entry.field) and not entry.count:
                unwritten = True  # an entry slot still zeros
            elif entry.tag == 330 and offset == first:
                offsets.extend(read_values(f, layout, entry, size, MAX_TAGS) or ())
            elif entry.tag in _READ:  # the values read_blind judges, where they lie apart
                values = read_values(f, layout, entry, size, _MAX_VALUES)
                digest.update(repr(values).encode())
    return IfdState(digest.digest(), unwritten)


def _version(v: tuple[int, ...] | None) -> str:
    return ".".join(map(str, v)) if v else "?"


def dng_refusal(path: Path) -> str | None:
    """What to tell of a DNG LibRaw refused as unsupported, as the sentence after LibRaw's
    words: damaged, newer than LibRaw (or compressed in a way this build does not decode), or
    either; None when ``path`` does not say it is a DNG (the caller words other formats)."""
    tags = read_dng_tags(path)
    if tags is None:
        return None
    if tags.damage:
        return (
            f"it is damaged ({'; '.join(tags.damage)}): its own tags are broken, so "
            "updating rawpy will not help. Copy the shot again from the camera's card, or "
            "save it again from the program that made it"
        )
    if tags.compression == JPEG_XL:
        return (
            "it is compressed as JPEG XL (DNG 1.7), which this LibRaw build does not "
            f"decode. Update rawpy ({pip_upgrade('rawpy')}) to one built with JPEG XL, or save "
            "DNGs with lossless JPEG compression (the converter's or camera's compatibility "
            "setting)"
        )
    needs = tags.backward or tags.version
    if needs is not None and needs[:2] > LIBRAW_DNG:
        return (
            f"it asks for a reader of DNG {_version(needs)} (its DNGVersion "
            f"{_version(tags.version)}), newer than the DNG {_version(LIBRAW_DNG)} this LibRaw "
            f"was written for. Update rawpy ({pip_upgrade('rawpy')}), or save the DNGs for an "
            "older DNG version (the converter's compatibility setting)"
        )
    compression = (
        ""
        if tags.compression in DNG_COMPRESSIONS
        else f"; its compression code {tags.compression} is none the DNG specification names"
    )
    return (
        f"its main image's tags look whole (DNGVersion {_version(tags.version)}{compression}), "
        "so it is either newer than this LibRaw reads or damaged in a way its tags do not "
        "show. Open it in another program (Adobe DNG Converter, darktable): if it opens, "
        f"update rawpy ({pip_upgrade('rawpy')}); if it does not, copy the shot again from the "
        "camera's card"
    )


def read_blind(path: Path) -> str | None:
    """Why LibRaw, which decodes ``path`` (a DNG) without a word, cannot have read the
    picture taken from it (the sentence's clause after "it names itself a DNG, but"); None
    when nothing its tags say shows that, or it is no DNG.

    Why: LibRaw decodes a CFA DNG whose CFAPattern is lost with a pattern taken from memory
    it never set (one read made a picture of red photosites only, the next a run-stopping
    IndexError), and one whose StripOffsets entry is lost with its pixels read from bytes
    that are not the picture's (measured, LibRaw 0.22.2: values 0 to 65535 of a picture of
    1017 to 59970, with no error and nothing printed). Only the file's tags can say so. A
    lost StripByteCounts alone is not said: LibRaw reads an uncompressed strip without it,
    the picture as taken."""
    tags = read_dng_tags(path)
    if tags is None:
        return None
    if tags.cfa_lost is not None:
        return (
            f"{tags.cfa_lost}: LibRaw would read it all the same, with a pattern of its own "
            "guessing, and not the picture taken"
        )
    if tags.data_lost is not None:
        return (
            f"{tags.data_lost} (where its picture lies in the file): LibRaw would read it all "
            "the same, its pixels from bytes that are not the picture's, and not the picture "
            "taken"
        )
    return None
