"""Image files of a session: linear 16-bit TIFF for fitting, 8-bit sRGB JPEG for viewers.

Writes are atomic (temporary file in the same folder, fsync, rename) and never replace an
existing file, so an interrupted or repeated write can never damage an image already captured.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import re
import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import SessionError
from rti_rig.core.shell_words import shown_path

#: The first bytes of the image files an acquisition holds: JPEG, PNG, TIFF (either byte
#: order; DNG and most camera RAW are TIFF too). One list for the header reads here and for
#: the readers that refuse an image given where text goes (:func:`looks_like_image`).
JPEG_MAGIC = b"\xff\xd8"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: a TIFF's first bytes, little- and big-endian, then a BigTIFF's (tifffile reads both)
TIFF_MAGIC = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")
#: Camera RAW file endings, the one list for the core and the drivers: the gphoto2 camera and
#: the planner's RAW preview use :func:`is_camera_raw` (the core may not import a driver, a
#: driver may import the core; ``folder_watch.RAW_SUFFIXES`` is this list).
#: :func:`read_image_any` does not decode them:
#: most are TIFF inside, so the header reader gives them a size (a DNG's, or the thumbnail
#: that opens a NEF), and OpenCV then fails on the CFA data or reads that thumbnail.
CAMERA_RAW_SUFFIXES = frozenset(
    {
        ".dng", ".cr2", ".cr3", ".crw", ".nef", ".nrw", ".arw", ".srf", ".sr2", ".orf",
        ".rw2", ".raf", ".pef", ".srw", ".3fr", ".iiq", ".erf", ".kdc", ".mos", ".x3f",
    }
)  # fmt: skip


def is_camera_raw(path: Path) -> bool:
    """Whether ``path`` is named as a camera RAW file (see :data:`CAMERA_RAW_SUFFIXES`)."""
    return Path(path).suffix.lower() in CAMERA_RAW_SUFFIXES


#: PNG colour types (PNG spec, IHDR) whose pixels carry an alpha sample: grey + alpha (4),
#: RGBA (6). PNG alpha is never premultiplied (the PNG spec: unassociated alpha only).
PNG_ALPHA_TYPES = {4: "grey + alpha", 6: "RGBA"}


def png_colour_type(path: Path) -> int | None:
    """A PNG's colour type from its IHDR (0 grey, 2 RGB, 3 palette, 4 grey + alpha, 6 RGBA);
    None for another file (told by its signature, not its name) or one too short to say (its
    reader says why).

    Why: OpenCV reads grey + alpha as four samples, the grey copied to three colours, with no
    way to tell it from RGBA: the watched folder, the replay rig and the fit had read a grey
    camera's PNGs as colour, their alpha dropped unsaid. One reading for the core and the
    drivers (a driver may import the core, not the other way)."""
    try:
        with Path(path).open("rb") as f:
            return _ihdr_colour_type(f.read(26))
    except OSError:
        return None


def _ihdr_colour_type(head: bytes) -> int | None:
    """The colour type in a file's first 26 bytes when they are a PNG's signature and IHDR."""
    if len(head) < 26 or head[:8] != PNG_MAGIC or head[12:16] != b"IHDR":
        return None
    return head[25]


def png_transparency(path: Path) -> str | None:
    """What of a PNG says transparency, which its readers drop: its colour type's alpha
    (``"grey + alpha"``, ``"RGBA"``) or a transparency key (``"tRNS"``: one grey or colour
    value, or palette entries, marked transparent); None for a PNG without, or another file.

    Why the key too: OpenCV drops it from a grey PNG and turns it into an alpha sample of a
    colour or palette one, which the readers then drop: either way it had gone unsaid, where
    an alpha channel was said. Read from the chunks before the pixels (the PNG spec puts tRNS
    before the first IDAT). The file is opened once for both (it had been opened once for
    the colour type and again for the chunks: two opens of every image of an acquisition)."""
    try:
        with Path(path).open("rb") as f:
            kind = _ihdr_colour_type(f.read(26))
            if kind is None:
                return None
            if kind in PNG_ALPHA_TYPES:
                return PNG_ALPHA_TYPES[kind]
            f.seek(8)
            while True:
                head = f.read(8)
                if len(head) < 8 or head[4:] in (b"IDAT", b"IEND"):
                    return None
                if head[4:] == b"tRNS":
                    return "tRNS"
                f.seek(int.from_bytes(head[:4], "big") + 4, 1)  # its data and CRC
    except OSError:
        return None


def png_alpha_note(names: Sequence[str], paths: Sequence[Path]) -> list[str]:
    """The one note of an acquisition (``paths[i]`` read for ``names[i]``) whose PNGs carry
    an alpha channel or a transparency key (:func:`png_transparency`), which their readers
    drop; none when no PNG does.

    Why once for the acquisition: the alpha carries no light, so the grey or colour samples
    are the picture, but the user should know it is left out (the replay rig and the fit had
    dropped it unsaid), in one line, not one per image. A transparency key is dropped alike:
    it marks a value as see-through, and that value is still what the camera measured."""
    kinds = {n: png_transparency(p) for n, p in zip(names, paths, strict=True)}
    alpha = [n for n, k in kinds.items() if k is not None and k != "tRNS"]
    keyed = [n for n, k in kinds.items() if k == "tRNS"]
    notes = []
    if alpha:
        shown = ", ".join(alpha[:3]) + (" ..." if len(alpha) > 3 else "")
        notes.append(
            f"{len(alpha)} of {len(names)} image(s) are PNGs with an alpha channel ({shown}), "
            "which carries no light: it was dropped and their grey or colour samples used"
        )
    if keyed:
        shown = ", ".join(keyed[:3]) + (" ..." if len(keyed) > 3 else "")
        notes.append(
            f"{len(keyed)} of {len(names)} image(s) are PNGs with a transparency key (tRNS: "
            f"{shown}), which marks a value see-through but carries no light: it was dropped "
            "and every pixel used as measured"
        )
    return notes


def opencv_as_stored(img: NDArray[Any], path: Path) -> NDArray[Any]:
    """``cv2.imread(path, IMREAD_UNCHANGED)``'s ``img`` as the file stores it: colour in RGB
    order, a grey + alpha PNG as grey (OpenCV gives B = G = R = grey and alpha,
    :func:`png_colour_type` tells it from RGBA), an alpha sample dropped (it carries no light).

    Why one function: the recorded-image reader and the planner's preview each converted
    OpenCV's channels themselves, and the preview had read a grey + alpha PNG as colour."""
    if img.ndim == 3 and img.shape[2] == 4 and png_colour_type(path) == 4:
        return np.ascontiguousarray(img[..., 0])
    if img.ndim == 3:
        return np.ascontiguousarray(img[..., 2::-1] if img.shape[2] >= 3 else img[..., 0])
    return img


def image_number(path: Path) -> tuple[int, str]:
    """The sort key of a session's numbered file (``image_NNN.*``): its number, then its name
    (a name without one sorts first).

    Why: by name, ``image_1000`` sorts before ``image_999``; the last image kept is the one
    with the highest number, not the last name."""
    stem = Path(path).name.split(".", 1)[0]
    digits = stem.rpartition("_")[2]
    return (int(digits) if digits.isdigit() else -1, Path(path).name)


def looks_like_image(raw: bytes) -> bool:
    """Whether ``raw`` starts as a JPEG, PNG or TIFF file does (an .lp or a rig config given
    an image is refused as one, not as text with NUL bytes)."""
    return raw.startswith((JPEG_MAGIC, PNG_MAGIC, *TIFF_MAGIC))


#: How a linear TIFF's ImageDescription begins when its pixels are a CFA mosaic (one colour per
#: photosite, ``decode.mode = "mosaic"``): the session writes it, and readers that need a
#: picture (``rti-rig fit``) refuse such a file by it rather than fit a checkerboard.
MOSAIC_TIFF_LABEL = "rti-rig: CFA mosaic"


def _srgb_curve(x: NDArray[np.floating]) -> NDArray[np.floating]:
    """The sRGB transfer curve (IEC 61966-2-1) on linear values in [0, 1]."""
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


#: the curve at every 16-bit level: a fit encodes every band and its pixel sample, and a table
#: lookup is cheaper than a power and gives one value per input however numpy vectorises it (a
#: fit's bands must give the same bytes in every process: the Dask runner's guarantee)
_SRGB_LUT = _srgb_curve(np.arange(65536, dtype=np.float64) / 65535.0).astype(np.float32)


def srgb_encode(linear: NDArray[np.floating]) -> NDArray[np.float32]:
    """The sRGB curve on linear values in units of full scale, at 16-bit resolution (exact for
    16-bit data, within 1/65535 of the input for any other), clipped to [0, 1]; NaN stays NaN
    (a missing observation). Worked in one float32 copy and a 16-bit index (a fit encodes its
    whole pixel sample at once)."""
    x = np.array(linear, dtype=np.float32, copy=True)
    missing = np.isnan(x)
    np.clip(x, 0.0, 1.0, out=x)
    x *= np.float32(65535.0)
    np.rint(x, out=x)
    x[missing] = 0.0
    np.take(_SRGB_LUT, x.astype(np.uint16), out=x)
    x[missing] = np.nan
    return x


def _srgb8_formula(pixels: NDArray[Any], white_level: int) -> NDArray[np.uint8]:
    x = np.clip(pixels.astype(np.float32) / float(white_level), 0.0, 1.0)
    return np.round(_srgb_curve(x) * 255.0).astype(np.uint8)


@functools.lru_cache(maxsize=8)
def _srgb8_table(white_level: int) -> NDArray[np.uint8]:
    """The 8-bit code of every 16-bit value at this white level (the formula, once per value)."""
    table = _srgb8_formula(np.arange(65536, dtype=np.uint16), white_level)
    table.setflags(write=False)
    return table


def linear_to_srgb8(pixels: NDArray[np.uint16], white_level: int) -> NDArray[np.uint8]:
    """Encode linear data with the sRGB transfer curve into 8 bits (for viewers and relight).

    16-bit pixels are looked up in a table of the formula's 65536 results: the same codes
    without the formula's five whole-image float32 temporaries, which took 1.4 GB for every
    24 MP frame a session wrote. Other types go through the formula.
    """
    if pixels.dtype == np.uint16 and white_level > 0 and float(white_level).is_integer():
        # indexing, not np.take: take converts the indices to a whole intp (int64) copy first
        return _srgb8_table(int(white_level))[pixels]
    return _srgb8_formula(pixels, white_level)


def _atomic_write(path: Path, data: bytes | Sequence[bytes | memoryview]) -> str:
    """Write bytes (or parts, one after the other) to a new file atomically; return its
    SHA-256."""
    if path.exists():
        raise SessionError(
            f"{shown_path(path)} already exists: refusing to overwrite a captured file"
        )
    parts = [data] if isinstance(data, bytes) else list(data)
    tmp = path.with_name(f".{path.name}.partial")
    digest = hashlib.sha256()
    try:
        with open(tmp, "wb") as fh:
            for part in parts:
                fh.write(part)
                digest.update(part)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError:
        # a write that failed (no space, read-only, I/O error) leaves no partial file behind
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        raise
    return digest.hexdigest()


#: Compression of the linear TIFFs a session writes. None (uncompressed) since 2026-11-24:
#: zlib took 1–1.8 s per 2.5-megapixel frame to write and 0.2–0.3 s to decode each time a fit
#: read it — most of `rti-rig fit`'s time (docs/benchmarks.md) — for files only 10–40 % smaller
#: (16-bit sensor noise compresses poorly). Readers accept both (core/tiff_rows.py).
LINEAR_TIFF_COMPRESSION: str | None = None
#: Rows per strip of an uncompressed linear TIFF: readers fetch a band of rows in one read.
LINEAR_TIFF_ROWS_PER_STRIP = 64


def write_linear_tiff(
    path: Path,
    pixels: NDArray[np.uint16],
    description: str | None = None,
    compression: str | None = LINEAR_TIFF_COMPRESSION,
    iccprofile: bytes | None = None,
) -> str:
    """Write a linear 16-bit TIFF (``description`` goes into ImageDescription); returns its
    SHA-256. ``compression``: None (default, see :data:`LINEAR_TIFF_COMPRESSION`) or "zlib".
    ``iccprofile``: an RGB ICC profile for the InterColorProfile tag of a colour image (a
    session's linear-sRGB TIFFs carry :func:`~rti_rig.core.image_colour.icc_profile`
    ``("linear")``, so that colour-managed viewers do not take them as sRGB-encoded and show
    them dark)."""
    import io

    import tifffile  # imported by the writer only: reading a config or planning never needs it

    buf = io.BytesIO()
    photometric = "rgb" if pixels.ndim == 3 else "minisblack"
    extra: dict[str, object] = {"description": description, "metadata": None} if description else {}
    if compression is None:
        extra["rowsperstrip"] = LINEAR_TIFF_ROWS_PER_STRIP
    if iccprofile is not None and pixels.ndim == 3:  # an RGB profile: colour images only
        extra["iccprofile"] = iccprofile
    tifffile.imwrite(buf, pixels, photometric=photometric, compression=compression, **extra)
    return _atomic_write(path, buf.getvalue())


def write_srgb_jpeg(path: Path, srgb8: NDArray[np.uint8], quality: int = 95) -> str:
    """Write an 8-bit sRGB JPEG (RGB order in, as OpenCV wants BGR on disk), marked sRGB when
    colour (Exif ColorSpace 1 and an sRGB ICC profile,
    :func:`~rti_rig.core.image_colour.tag_jpeg_srgb`; a grey one has no RGB colour space);
    returns its SHA-256. Still a plain baseline JFIF, as relight and RTIBuilder read it."""
    from rti_rig.core.image_colour import tagged_jpeg_parts

    data = _encode_jpeg(path, srgb8, quality)
    return _atomic_write(path, tagged_jpeg_parts(data) if srgb8.ndim == 3 else data)


def write_untagged_jpeg(path: Path, srgb8: NDArray[np.uint8], quality: int = 95) -> str:
    """:func:`write_srgb_jpeg` with no colour-space tag: for pixels through the sRGB curve
    that are not sRGB colours (camera RGB from a RAW with no colour matrix, a CFA mosaic),
    which viewers must not be told are sRGB; returns its SHA-256."""
    return _atomic_write(path, _encode_jpeg(path, srgb8, quality))


def _encode_jpeg(path: Path, srgb8: NDArray[np.uint8], quality: int) -> bytes:
    """The baseline JPEG of ``srgb8`` (RGB order in), 4:4:4 where colour."""
    import cv2  # on use: importing the controller must not load a device library

    img = srgb8[..., ::-1] if srgb8.ndim == 3 else srgb8
    params = [cv2.IMWRITE_JPEG_QUALITY, quality]
    if img.ndim == 3 and hasattr(cv2, "IMWRITE_JPEG_SAMPLING_FACTOR"):
        # full-resolution colour (4:4:4): 4:2:0 chroma subsampling moves colours at patch and
        # demosaic edges by several code values; 4:4:4 keeps them within 1
        params += [cv2.IMWRITE_JPEG_SAMPLING_FACTOR, cv2.IMWRITE_JPEG_SAMPLING_FACTOR_444]
    ok, enc = cv2.imencode(".jpg", np.ascontiguousarray(img), params)
    if not ok:
        raise SessionError(f"could not encode {path.name} as JPEG")
    return enc.tobytes()


def pixels_sha256(pixels: NDArray[Any]) -> str:
    """SHA-256 of an image's pixels, independent of the file that holds them: its shape, its
    sample type and its samples in row order, little-endian.

    Why, besides the file's own checksum: a linear TIFF re-saved by another tool with the same
    pixels (a tag added, recompressed) differs byte for byte, yet what a fit reads is
    unchanged; an edit saved over it changes the pixels. The pixel checksum tells the two
    apart (:func:`tiff_pixels_sha256` reads a file's back)."""
    arr = np.ascontiguousarray(pixels)
    if arr.dtype.byteorder == ">" or (arr.dtype.byteorder == "=" and not _LITTLE):
        arr = arr.astype(arr.dtype.newbyteorder("<"))
    h = pixels_hasher(arr.shape, arr.dtype)
    h.update(memoryview(arr.reshape(-1).view(np.uint8)))  # the GIL is released while hashing
    return h.hexdigest()


def pixels_hasher(shape: tuple[int, ...], dtype: np.dtype[Any]) -> Any:
    """The SHA-256 of :func:`pixels_sha256` before any sample: fed an image's little-endian
    samples in row order, a band at a time, it gives that checksum (how a reader that goes
    through every row anyway takes it without reading the file again)."""
    return hashlib.sha256(f"{tuple(shape)}|{dtype.kind}{dtype.itemsize}|".encode())


_LITTLE = np.little_endian


def tiff_pixels_sha256(path: Path) -> str | None:
    """:func:`pixels_sha256` of the first image of the TIFF at ``path`` (None if it cannot be
    decoded: damaged, cut short, or no TIFF at all)."""
    import tifffile

    try:
        return pixels_sha256(tifffile.imread(path))
    except Exception:  # tifffile raises many kinds for a damaged file; None says "unreadable"
        return None


def read_linear_tiff(path: Path) -> NDArray[np.uint16]:
    import tifffile

    return tifffile.imread(path)


#: How rti-rig's own linear TIFFs begin their ImageDescription (a session's, or a kept-aside
#: image's): what they say of their pixels follows.
OWN_TIFF_LABEL = "rti-rig:"
_WHITE_SAID = re.compile(r", 16-bit, white level (\d+)\b")


def labelled_white_level(description: str) -> int | None:
    """The white level an rti-rig linear TIFF's label states (``rti-rig: linear sRGB, 16-bit,
    white level 4095 (...)``), or None where it states none (another writer's TIFF, a RAW's or
    a mosaic's label).

    Why: a session of a replayed 12-bit acquisition holds the recorded codes as they were
    (white 4095), and its label is the only place that says so: every later reader of the
    session (its fit and QA, an adaptive resume) takes its white from here."""
    if not description.startswith(OWN_TIFF_LABEL):
        return None
    # the last one: a colour profile's name, said before it, is the file's own words
    found = _WHITE_SAID.findall(description)
    level = int(found[-1]) if found else 0
    return level if 1 <= level <= 65535 else None  # a label edited to 0 states nothing


def linear_tiff_white_level(path: Path) -> int | None:
    """The white level ``path``'s label states (:func:`labelled_white_level`), read from its
    main image's header alone; None where it states none or the file is no TIFF."""
    import tifffile

    try:
        with tifffile.TiffFile(path) as tif:
            return labelled_white_level(str(tiff_main_image(tif).keyframe.description or ""))
    except (OSError, ValueError, IndexError, KeyError, struct.error, tifffile.TiffFileError):
        return None  # a file cut short or not a TIFF: no label said


def jpeg_truncation(path: Path) -> str | None:
    """Why the JPEG at ``path`` is cut short, or None when it is whole (or not a JPEG).

    OpenCV decodes a truncated JPEG without an error (libjpeg only prints "Premature end of
    JPEG file" and fills the rest with grey), so a copy cut short by a full card or an
    interrupted transfer would be fitted as if it were an image. A whole JPEG ends its
    compressed data with the end-of-image marker FF D9, which cannot occur inside that data
    (a data byte FF is followed by 00 or a restart marker); the header segments before the
    first scan (EXIF, whose thumbnail has its own FF D9) are skipped by their lengths."""
    data = Path(path).read_bytes()
    if not data.startswith(JPEG_MAGIC):
        return None
    pos = 2
    while pos + 4 <= len(data):
        if data[pos] != 0xFF:
            return f"corrupt marker at byte {pos}"
        marker = data[pos + 1]
        if marker == 0xFF:  # fill byte
            pos += 1
            continue
        if marker == 0xD9:
            return "no image data (end-of-image before the first scan)"
        length = int.from_bytes(data[pos + 2 : pos + 4], "big")
        if marker == 0xDA:  # start of scan: the compressed data follows
            if data.find(b"\xff\xd9", pos + 2 + length) < 0:
                return "it ends before its end-of-image marker (cut short)"
            return None
        pos += 2 + length
    return "it ends inside its header (cut short)"


def image_truncation(path: Path) -> str | None:
    """Why the JPEG, PNG or TIFF at ``path`` is cut short, or None when it is whole (or of
    another kind): read from its ends and header, without decoding the pixels.

    A PNG or TIFF cut short by a full card or an interrupted copy keeps a whole header, so
    :func:`header_layout` gives it a size; the replay rig's check before a session had passed
    it ("undamaged and readable") and the session stopped at its image part-way. A whole PNG
    ends with its IEND chunk; a whole TIFF holds every strip or tile its first page lists."""
    p = Path(path)
    with open(p, "rb") as fh:
        head = fh.read(8)
        if head.startswith(PNG_MAGIC):
            size = fh.seek(0, os.SEEK_END)
            fh.seek(max(0, size - 4096))
            if b"IEND" not in fh.read():  # the last chunk; writers may pad after it
                return "it ends before its IEND chunk (cut short)"
            return None
    if head[:4] in TIFF_MAGIC:
        # the image read (:func:`tiff_main_image`), not every page (None, too, where tifffile
        # cannot parse it: the decoder names the problem later)
        extent = tiff_extent(p, main_image=True)
        size = p.stat().st_size
        if extent is not None and extent[1] > size:
            return f"its image data runs {extent[1] - size} bytes past its end (cut short)"
        return None
    return jpeg_truncation(p)


class SeveralFullSizeImages(ValueError):
    """A TIFF holding more than one full-size image, none a thumbnail of another (raised by
    :func:`tiff_main_image`). Its own kind, not a damaged file's: the file is whole and reads,
    so "copy it again" or "wait for it" would not help; saving it as a TIFF of one image does."""


def tiff_main_image(tif: Any) -> Any:
    """The full-resolution image of an open :class:`tifffile.TiffFile`, as a page series
    (``.keyframe`` its first page, ``.asarray()`` its pixels, ``.pages`` its pages).

    Why not the first page: some cameras and RTIBuilder exports put a small thumbnail in IFD0
    and the full image in a later IFD or in a SubIFD (as DNG does); reading IFD0 had replayed
    and checked an acquisition at thumbnail size (16x12 for a 64x48 image) without a word.
    Images marked reduced-resolution (NewSubfileType bit 0) or as a mask (bit 2) are
    thumbnails and previews; of the others, the largest is the image. Two different images of
    that size (neither a thumbnail of the other) are refused: which one was meant is not known.
    """
    candidates = [level for series in tif.series for level in series.levels]
    if not candidates:
        raise ValueError("it holds no image")

    def flags(series: Any) -> int:
        return int(getattr(series.keyframe, "subfiletype", 0) or 0)

    def area(series: Any) -> int:
        return int(series.keyframe.imagelength) * int(series.keyframe.imagewidth)

    full = [s for s in candidates if not flags(s) & 0b101] or candidates
    best = max(full, key=area)
    rivals = [s for s in full if s is not best and area(s) == area(best)]
    if rivals:
        sizes = ", ".join(
            f"{int(s.keyframe.imagewidth)}x{int(s.keyframe.imagelength)} {s.dtype}"
            for s in (best, *rivals)
        )
        raise SeveralFullSizeImages(
            f"it holds {1 + len(rivals)} full-size images ({sizes}) and which one is the "
            "photograph is not known; save it again as a TIFF of one image"
        )
    return best


def tiff_one_image(tif: Any) -> Any:
    """:func:`tiff_main_image`, refused as :class:`SeveralFullSizeImages` also when it is a
    stack: pages of one size and type, which tifffile reads as one series (2, H, W, …).

    Why: a reader wanting one picture (the watched folder, the plan's preview) had handed
    such a file on as one array and had it refused by its shape, the file and the fix
    unnamed, where two images of different types were refused as what they are."""
    main = tiff_main_image(tif)
    if len(main.pages) > 1:
        key = main.keyframe
        raise SeveralFullSizeImages(
            f"it holds {len(main.pages)} full-size images ({int(key.imagewidth)}x"
            f"{int(key.imagelength)} {main.dtype}, one per page) and which one is the "
            "photograph is not known; save it again as a TIFF of one image"
        )
    return main


def is_tiff_file(path: Path) -> bool:
    """Whether ``path`` starts as a TIFF does (classic or BigTIFF, either byte order).

    Why by its bytes, not its suffix: a preview or shot saved as ``.TIF``, ``.tiff`` or with
    no suffix at all is read the same way; the readers that pick a TIFF's full-resolution
    image had each opened the file to check these four bytes themselves."""
    with open(path, "rb") as fh:
        return fh.read(4) in TIFF_MAGIC


def tiff_main_pixels(tif: Any) -> NDArray[Any]:
    """The pixels of an open TIFF's full-resolution image (:func:`tiff_main_image`), samples
    last, (H, W) or (H, W, samples), whatever its planar configuration.

    Why one function: the recorded-image reader, the planner's preview and the replay's row
    view each picked the image and put its samples last in the same two lines; a reader that
    forgot the second had refused a planar TIFF as an image 3 pixels high."""
    image = tiff_main_image(tif)
    return tiff_samples_last(image.asarray(), tiff_is_planar(image.keyframe))


def tiff_several_images(path: Path) -> str | None:
    """Why the TIFF at ``path`` cannot give one image, when it holds two or more full-size
    images (:class:`SeveralFullSizeImages`: the file's name, then its words); None for any
    other file, or a TIFF tifffile cannot parse (its reader names that problem).

    Why apart from the unreadable files: such a file is whole and reads, so a check that
    listed it with them had advised copying it again from the camera or card, which gives
    the same two images back."""
    p = Path(path)
    if not is_tiff_file(p):
        return None
    import tifffile

    try:
        with tifffile.TiffFile(p) as tif:
            tiff_main_image(tif)
    except SeveralFullSizeImages as exc:
        return f"{p.name}: {exc}"
    except Exception:  # tifffile raises many kinds; the decoder names the problem later
        return None
    return None


def tiff_extent(path: Path, main_image: bool = False) -> tuple[int, int] | None:
    """Where the TIFF ``path``'s own structure names last lies: (start, end) of the strip,
    tile or IFD that ends furthest into the file, over all its pages, or with ``main_image``
    over the pages of the image a reader takes (:func:`tiff_main_image`:
    not a thumbnail before it, nor a SubIFD it would skip);
    None when tifffile cannot parse its IFDs at all, or one names no data (not all written
    yet, or damaged: not known which).

    Why one function: whether a TIFF is cut short (:func:`image_truncation`, before a
    session) and whether a watched folder's TIFF that will not decode is still being written
    (its IFDs name data past its end) or whole and damaged are the same reading of its IFDs,
    and had been written twice."""
    import tifffile

    try:
        with tifffile.TiffFile(path) as tif:
            last = (0, 0)
            read = tiff_main_image(tif).pages if main_image else tif.pages
            for page in read:
                ifd = int(getattr(page, "offset", 0))
                data = [
                    (int(o), int(o) + int(n))
                    for o, n in zip(
                        getattr(page, "dataoffsets", ()),
                        getattr(page, "databytecounts", ()),
                        strict=False,
                    )
                ]
                if not data:  # an IFD naming no data: damaged, or not all written yet
                    return None
                last = max([last, (ifd, ifd + 2), *data], key=lambda piece: piece[1])
            return last
    except Exception:  # IFDs that will not parse (tifffile raises many kinds): nothing known
        return None


def header_layout(path: Path) -> tuple[int, int, bool] | None:
    """(height, width, colour) from the file's header alone (JPEG frame header, PNG IHDR, the
    TIFF full-resolution image's IFD), without decoding the pixels; ``colour`` as
    :func:`read_image_any` would return it (3 channels, not grey). None when the header does
    not say (another format, or a damaged or empty file: the decoder will say why)."""
    info = _header_info(path)
    return None if info is None else info[:3]


def header_bit_depth(path: Path) -> int | None:
    """Bits per sample from the file's header alone (8 for a JPEG or an 8-bit PNG/TIFF, 16 for
    a 16-bit one), None when the header does not say. Why: 8-bit images are read as sRGB and
    16-bit ones as linear, so an acquisition mixing them is said before it is used."""
    info = _header_info(path)
    return None if info is None else info[3]


def _header_info(path: Path) -> tuple[int, int, bool, int] | None:
    """(height, width, colour, bits per sample) from the header (see :func:`header_layout`)."""
    p = Path(path)
    with open(p, "rb") as fh:
        head = fh.read(64 * 1024)
    if head.startswith(PNG_MAGIC) and head[12:16] == b"IHDR" and len(head) >= 26:
        # colour type 0 grey, 4 grey + alpha; 2 RGB, 3 palette (decoded to RGB), 6 RGBA
        colour = head[25] not in (0, 4)
        bits = 8 if head[25] == 3 else int(head[24])  # a palette's entries are 8-bit samples
        return int.from_bytes(head[20:24], "big"), int.from_bytes(head[16:20], "big"), colour, bits
    if head[:4] in TIFF_MAGIC:
        import tifffile

        try:
            with tifffile.TiffFile(p) as tif:
                page = tiff_main_image(tif).keyframe  # not a thumbnail in IFD0
                colour = page.samplesperpixel >= 3
                bits = int(page.bitspersample)
                return int(page.imagelength), int(page.imagewidth), colour, bits
        except Exception:  # tifffile raises many kinds; the decoder names the problem later
            return None
    if not head.startswith(JPEG_MAGIC):
        return None
    data = head if len(head) < 64 * 1024 else p.read_bytes()
    pos = 2
    while pos + 10 <= len(data) and data[pos] == 0xFF:
        marker = data[pos + 1]
        if marker == 0xFF:
            pos += 1
            continue
        length = int.from_bytes(data[pos + 2 : pos + 4], "big")
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):  # start of frame
            height = int.from_bytes(data[pos + 5 : pos + 7], "big")
            width = int.from_bytes(data[pos + 7 : pos + 9], "big")
            # components: 1 grey, 3 YCbCr, 4 CMYK; sample precision 8 (12 in rare files)
            return height, width, data[pos + 9] != 1, int(data[pos + 4])
        if marker == 0xDA:
            return None
        pos += 2 + length
    return None


def refuse_truncated_jpeg(path: Path) -> None:
    """Raise :class:`SessionError` naming ``path`` if it is a truncated JPEG."""
    why = jpeg_truncation(path)
    if why is not None:
        raise SessionError(
            f"image {shown_path(path)} is a damaged JPEG: {why}; copy it again from the camera or "
            "card (a truncated image would be read with its missing part grey)"
        )


def read_jpeg_rgb(path: Path) -> NDArray[np.uint8]:
    from rti_rig.core import opencv_files  # OpenCV imported only when needed

    if Path(path).is_file():
        refuse_truncated_jpeg(path)  # before OpenCV, which decodes it with a grey part
    img = opencv_files.imread(path)
    if img is None:
        raise SessionError(f"cannot read image {shown_path(path)}")
    return img[..., ::-1] if img.ndim == 3 else img


def tiff_is_planar(page: Any) -> bool:
    """Whether a TIFF page stores its colour samples as separate planes (PlanarConfiguration
    2, Photoshop's "Per Channel" pixel order), which tifffile returns samples first."""
    return int(page.planarconfig) == 2 and int(page.samplesperpixel) > 1


def tiff_samples_last(pixels: NDArray[Any], planar: bool) -> NDArray[Any]:
    """A TIFF's pixels as (H, W) or (H, W, samples) whatever its planar configuration: a
    planar RGB TIFF decodes to (3, H, W), which had been taken for an image 3 pixels high
    (the replay rig stopped at its first capture, the fit at its export)."""
    if planar and pixels.ndim == 3:
        return np.ascontiguousarray(np.moveaxis(pixels, 0, -1))
    return pixels


def colour_or_grey(pixels: NDArray[Any]) -> NDArray[Any]:
    """(H, W, 3) colour or (H, W) grey from an RGB-ordered image with any extra samples: an
    alpha channel (RGBA, or grey + alpha) carries no light and is dropped, as
    :func:`header_layout` counts such images (3 samples or more: colour)."""
    if pixels.ndim != 3 or pixels.shape[2] == 3:
        return pixels
    return pixels[..., :3] if pixels.shape[2] > 3 else pixels[..., 0]


def _not_8_or_16_bit(path: Path, dtype: Any, shape: tuple[int, ...]) -> str:
    """The refusal of an image whose pixels no frame holds, with what to give instead."""
    return (
        f"image {shown_path(path)}: {np.dtype(dtype)} {tuple(shape)} is not 8/16-bit grey or RGB; "
        "save it again as an 8-bit (sRGB) or 16-bit (linear) TIFF of one image"
    )


def tiff_sample_problem(path: Path) -> str | None:
    """Why :func:`read_image_any` would refuse a TIFF that reads — float or 32-bit samples (an
    HDR export), a stack of pages — told from its header, without decoding the pixels; None
    when it would read it, or when the file is no TIFF or is damaged (its decoder says why).

    :func:`header_layout` gives such a file a size like any other: the replay rig's check
    before a session had passed it ("undamaged and readable") and the session stopped at its
    image part-way, telling the user to resume into the same stop."""
    p = Path(path)
    if not is_tiff_file(p):
        return None
    import tifffile

    try:
        with tifffile.TiffFile(p) as tif:
            image = tiff_main_image(tif)
            dtype = image.keyframe.dtype
            shape = tuple(int(n) for n in image.shape)
    except Exception:  # tifffile raises many kinds; the decoder names the problem later
        return None
    if dtype is None or (np.dtype(dtype) in (np.uint8, np.uint16) and len(shape) in (2, 3)):
        return None
    return _not_8_or_16_bit(p, dtype, shape)


def read_image_any(path: Path) -> NDArray[np.uint8] | NDArray[np.uint16]:
    """A recorded image as stored: 8-bit (JPEG, 8-bit PNG/TIFF) or 16-bit (TIFF, PNG), RGB
    order, shape (H, W) or (H, W, 3) (a TIFF's full-resolution image, :func:`tiff_main_image`;
    a grey + alpha PNG is grey, :func:`png_colour_type`), an alpha channel dropped; refused
    with the file's name if it cannot be read."""
    p = Path(path)
    if p.suffix.lower() in (".tif", ".tiff"):
        import tifffile

        try:
            with tifffile.TiffFile(p) as tif:
                img = tiff_main_pixels(tif)  # not a thumbnail in IFD0
        except Exception as exc:  # tifffile raises many kinds; the user needs the file's name
            raise SessionError(f"cannot read image {shown_path(p)}: {exc}") from None
        if img.dtype not in (np.uint8, np.uint16) or img.ndim not in (2, 3):
            raise SessionError(_not_8_or_16_bit(p, img.dtype, img.shape))
        return colour_or_grey(img)
    from rti_rig.core import opencv_files

    if not p.is_file():  # said here, before OpenCV prints its own warning line about it
        raise SessionError(f"cannot read image {shown_path(p)}: there is no such file")
    if p.stat().st_size == 0:  # it had been "missing, or not an image OpenCV decodes"
        raise SessionError(
            f"cannot read image {shown_path(p)}: the file is empty (0 bytes: cut off while "
            "copied, or a full card?)"
        )
    refuse_truncated_jpeg(p)  # before OpenCV, which decodes it with a grey part
    img = opencv_files.imread(p)
    if img is None:
        raise SessionError(
            f"cannot read image {shown_path(p)} (missing, or not an image OpenCV decodes)"
        )
    if img.dtype not in (np.uint8, np.uint16):
        raise SessionError(f"image {shown_path(p)}: {img.dtype} is not 8- or 16-bit")
    return np.ascontiguousarray(opencv_as_stored(img, p))
