"""What a TIFF's own bytes prove about whether it is all written (pure reads, no decoding).

Why: a watched folder's TIFF that will not read is either still being written (or copied)
or damaged, and only the second may stop a session at once. Writers order their bytes
differently: libtiff (OpenCV, ImageMagick, GIMP, darktable) writes its header with a first-IFD
offset of 0, then the strips, then the IFD, and patches the header last; tifffile writes its
header naming an IFD at offset 8, leaves that slot zeroed while the data goes out, then writes
the IFD. A copy (cp, rsync, SMB, a Wi-Fi upload) that pauses is cut anywhere. Until the IFD is
there, tifffile reads such a file as an image of no pixels, which had been called damaged.
Only bytes that are there can prove damage: a header naming an IFD that lies wholly inside
the file, with a tag count no writer in the middle of its work leaves.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

# what a TIFF's bytes are is read in one place (:mod:`.tiff_ifd`); this module judges them
from rti_rig.drivers.cameras.tiff_ifd import (
    MAX_TAGS,
    TIFF_TYPES,
    read_count,
    read_entries,
    read_header,
)


@dataclass(frozen=True)
class FirstIfd:
    """A TIFF's first IFD, all of it inside the file: where it lies and its entries' types."""

    offset: int
    #: where the IFD ends (its next-IFD offset included)
    end: int
    #: the data type of each entry, as written
    types: tuple[int, ...]

    @property
    def garbled(self) -> bool:
        """Whether an entry has a data type no TIFF has: no writer writes one, so the IFD
        itself is damaged (a zero type is a slot not filled yet, and is not counted)."""
        return any(t != 0 and t not in TIFF_TYPES for t in self.types)


def first_ifd(path: Path) -> FirstIfd | None:
    """``path``'s first IFD when its header names one (a non-zero offset) lying wholly inside
    the file with a tag count between 1 and :data:`MAX_TAGS`; None otherwise.

    None for a file that could still be in the middle of being written: a header not all
    there, libtiff's header whose IFD offset is not patched yet (0), an offset past the end
    (a copy cut short of a file whose IFD comes last), or tifffile's IFD slot still zeros
    (a count of 0). None too when the file cannot be read (nothing is known then)."""
    try:
        size = path.stat().st_size
        with path.open("rb") as f:
            named = read_header(f)
            if named is None:
                return None
            layout, offset = named
            if offset < layout.header or offset + layout.count_size > size:
                return None
            count = read_count(f, layout, offset)
            if count is None:
                return None
            end = layout.ifd_end(offset, count)
            if not 1 <= count <= MAX_TAGS or end > size:
                return None
            entries = read_entries(f, layout, offset, count)
    except OSError:
        return None
    if len(entries) < count:
        return None
    return FirstIfd(offset, end, tuple(e.type for e in entries))


def ifd_garbage(path: Path) -> str | None:
    """Why ``path``'s first IFD is garbage no writer on its way leaves, as a phrase ("its
    first IFD, at byte 8, gives a tag count of 23125 …"); None when it may yet be written, or
    is not known to be garbage, or the file cannot be read.

    Why: only :func:`first_ifd`'s whole, plausible IFD had been judged, so a TIFF whose header
    names an IFD inside the file that holds a count over :data:`MAX_TAGS` (tifffile refuses it
    as "suspicious"), or whose written entries have types no TIFF has, cost ``timeout_s``
    before it was named. A writer's or a copy's IFD not written yet reads otherwise: libtiff's
    header names none (0) until the IFD is there, tifffile's slot is zeros (a count of 0), a
    share that sizes a file first reads zeros where it has not filled, and a copy cut short
    ends inside an IFD whose count and entries so far are the writer's own. So a non-zero
    offset inside the header, a count over :data:`MAX_TAGS`, a count of 0 (TIFF 6.0: every
    IFD has at least one entry) followed by bytes that are not zeros (an offset landing in
    pixel data: a writer's slot not written yet is zeros throughout), or, in an IFD running
    past the file's end, an entry in the file with a non-zero type no TIFF has is damage (a
    whole IFD with an unknown type is left to the decode: TIFF 6.0 tells readers to skip
    such a field). (Whether the file's size is steady and its end written is the caller's
    to add.)"""
    try:
        size = path.stat().st_size
        with path.open("rb") as f:
            named = read_header(f)
            if named is None:
                return None
            layout, offset = named
            header, count_size = layout.header, layout.count_size
            if 0 < offset < header:
                return (
                    f"its header names its first IFD at byte {offset}, inside the "
                    f"{header}-byte header"
                )
            if offset == 0 or offset + count_size > size:
                return None  # none named yet (libtiff), or past the end (a copy cut short)
            count = read_count(f, layout, offset)
            if count is None:
                return None
            if count == 0:
                # TIFF 6.0 (p. 14): "each IFD must have at least one entry", and libtiff
                # refuses a count of 0; a writer's IFD not written yet is zeros throughout
                # (tifffile's reserved slot, a share's unfilled bytes), so a 0 count is a
                # slot to wait for only while the first entry and next-IFD offset after it
                # read as zeros too. Written bytes there (pixel data under a header that
                # names the wrong offset) will not turn into an IFD.
                if any(f.read(layout.entry_size + layout.offset_size)):
                    return (
                        f"its first IFD, at byte {offset}, gives a tag count of 0, which no "
                        "finished IFD has, while the bytes after it are written, where an IFD "
                        "not written yet reads as zeros"
                    )
                return None
            if count > MAX_TAGS:
                return (
                    f"its first IFD, at byte {offset}, gives a tag count of {count}, more than "
                    f"any writer writes ({MAX_TAGS}); a writer's IFD not written yet reads 0"
                )
            in_file = (size - offset - count_size) // layout.entry_size
            if count <= in_file:
                # a whole IFD: an entry of a type this reader does not know is the decode's to
                # judge (TIFF 6.0 tells readers to skip such fields; tifffile does, and reads
                # the image), never a reason to stop a good shot
                return None
            # the entries that are in the file of an IFD that runs past its end (a copy cut
            # short holds only the first ones, each as its writer wrote it)
            entries = read_entries(f, layout, offset, in_file)
    except OSError:
        return None
    for n, entry in enumerate(entries):
        if entry.type != 0 and entry.type not in TIFF_TYPES:
            return (
                f"entry {n + 1} of its first IFD, at byte {offset}, has data type "
                f"{entry.type}, which no TIFF has"
            )
    return None


#: TIFF compressions the reader (tifffile with imagecodecs) decodes for a camera's 16-bit
#: RGB image, and what a program's save dialog calls them (the advice names the first three)
READ_COMPRESSIONS = {
    1: "uncompressed",
    5: "LZW",
    8: "Deflate (zlib)",
    32946: "Deflate (zlib)",
    32773: "PackBits",
}

#: said to whoever saves a TIFF in a compression the reader does not decode
SAVE_READABLE = "save TIFFs uncompressed, or with LZW or Deflate (zlib) compression"
#: asked of a TIFF that will not read and may yet be incomplete (one reader's refusal, and the
#: folder watch's while it waits): one wording for both
COMPLETE_TIFF_ADVICE = "is it a complete TIFF (not one still being written, or a copy cut short)?"
#: said of a whole TIFF that is damaged: waiting will not mend it, saving it again may
SAVE_AGAIN = (
    "Save the shot again from the camera's program, or check the disk or share it is saved on"
)


def unread_compression(path: Path, said: str) -> str | None:
    """The name and code of ``path``'s first-page compression when it is none the reader
    decodes and the reader's refusal ``said`` names it ("EER_V0 (TIFF compression 65000)");
    None otherwise (a readable compression whose data is damaged, or no TIFF to read).

    Why: tifffile refuses such a file with only the code's enum ("COMPRESSION.EER_V0:
    65000"), and the file had been called damaged, with advice to check the disk or share,
    while saving it in another compression is all it takes."""
    import tifffile

    try:
        with tifffile.TiffFile(path) as tif:
            code = int(tif.pages[0].compression)
    except Exception:  # nothing read: not known
        return None
    if code in READ_COMPRESSIONS:
        return None
    try:
        name = tifffile.COMPRESSION(code).name
    except ValueError:
        name = ""
    if str(code) not in said and not (name and name in said):
        return None  # refused for another reason (its data), not for its compression
    return f"{name} (TIFF compression {code})" if name else f"TIFF compression {code}"
