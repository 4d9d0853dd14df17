"""RAW files to linear 16-bit frames: LibRaw (rawpy) reads the file, the rest is ours.

Why a module of its own: every camera path that yields RAW (gphoto2 downloads, watched folders,
the simulated camera's DNGs) must produce *the same* linear data, so they all call
:func:`decode_raw`. LibRaw only unpacks the photosites and the metadata (CFA pattern, black
levels per channel, white level, white balance, colour matrix, orientation); black removal,
white balance, demosaic and colour are done here, because LibRaw's ``postprocess`` subtracts
each channel's black but scales every channel by ``white − min(black)``: with unequal black
levels per CFA site that is a per-channel gain error of ``(black_c − black_min) / (white −
black_min)`` (2.6 % for blacks 512/600 at white 4095). Here each site is normalised by its own
``white − black_c`` exactly. Nothing is automatic (no auto-bright, no rescaling to the data
maximum), nothing is rotated.
"""

from __future__ import annotations

import io
import os
import sys
import tempfile
import threading
from collections.abc import Iterator
from contextlib import AbstractContextManager, contextmanager, nullcontext, suppress
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import rawpy
from numpy.typing import NDArray

from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError
from rti_rig.core.shell_words import pip_upgrade, shown_path
from rti_rig.drivers.cameras.dng_tags import dng_refusal, read_blind
from rti_rig.drivers.cameras.settings import RawDecodeSettings

DECODER = "raw-decode"


class RawDecodeError(CaptureError):
    """A RAW file that would not decode, with what is known as fields: ``path`` (the file
    read, None for bytes), ``problem`` (what is wrong with it and what to do: the sentence
    after the file's name), ``libraw_error`` (LibRaw's error kind, "LibRawIOError"; None when
    the refusal is ours), ``libraw_said`` (LibRaw's own words, as text) and
    ``libraw_printed`` (the lines LibRaw printed about the file, its name taken off).

    Why fields: a caller that names another file than the one read (a watched folder's file,
    of which the session's copy was decoded; a camera's file, downloaded under another name)
    had rewritten the path inside this message by string replacement, LibRaw's own words
    included, or cut it off at a fixed prefix. :meth:`about` words it for any file."""

    def __init__(
        self,
        path: Path | None,
        problem: str,
        *,
        libraw_error: str | None = None,
        libraw_said: str | None = None,
        libraw_printed: tuple[str, ...] = (),
    ) -> None:
        self.path = path
        self.problem = problem
        self.libraw_error = libraw_error
        self.libraw_said = libraw_said
        self.libraw_printed = libraw_printed
        super().__init__(DECODER, self.about("<bytes>" if path is None else path), "decode")

    def about(self, file: Path | str) -> str:
        """The refusal naming ``file`` as the one that would not decode."""
        return f"{shown_path(file)}: {self.problem}"


def libraw_named() -> str:
    """The installed LibRaw and the rawpy that bundles it, as a refusal names them."""
    return f"LibRaw {'.'.join(map(str, rawpy.libraw_version))} (rawpy {rawpy.__version__})"


def libraw_words(exc: BaseException) -> str:
    """LibRaw's own words for ``exc`` as text: rawpy raises them as bytes, whose repr
    ("b'Input/output error'") had reached the user's sentence."""
    said = exc.args[0] if exc.args else ""
    if isinstance(said, bytes | bytearray):
        said = bytes(said).decode("utf-8", "replace")
    return str(said) or type(exc).__name__


#: the name LibRaw gives a file it reads from memory in the lines it prints
LIBRAW_BUFFER_NAME = "unknown file"

#: one capture of fd 2 at a time: fd 2 is the process's, and two decoding threads each
#: saving and restoring it would leave the second's sink in place for good
_FD2 = threading.Lock()


@contextmanager
def libraw_printed(name: str, into: list[str]) -> Iterator[None]:
    """Hold what C code writes to fd 2 while LibRaw reads ``name`` (the path given to it, or
    :data:`LIBRAW_BUFFER_NAME`); on exit, put LibRaw's lines about it into ``into`` without
    their "``name``: " prefix ("Unexpected end of file"), and write any other line back to
    fd 2, so another thread's output is held back for the decode, never lost.

    Why: LibRaw's data-error handler prints its own line straight to the C stderr, naming the
    file it read: a watched folder's session copy (``raw/.incoming/...``), a file the user
    never saw, appeared on the terminal beside rti-rig's own refusal. A redirect of Python's
    ``sys.stderr`` does not catch a C ``fprintf``; fd 2 itself is swapped (``os.dup2``) and
    always restored. Where fd 2 cannot be swapped (none open), LibRaw runs as it is."""
    with suppress(AttributeError, OSError, ValueError):
        sys.stderr.flush()  # Python's own buffered lines go out first, not into the sink
    with _FD2:
        try:
            saved = os.dup(2)
        except OSError:
            yield
            return
        try:
            with tempfile.TemporaryFile() as sink:
                # the swap inside the try, and the restore in a finally of its own: a signal
                # (Ctrl-C, SIGTERM raised as an exception) landing just after the swap, or in
                # the flush before the restore, had left fd 2 on the sink for good, every later
                # line (the run's own error, its teardown) written to a deleted file
                try:
                    os.dup2(sink.fileno(), 2)
                    yield
                finally:
                    try:
                        with suppress(AttributeError, OSError, ValueError):
                            sys.stderr.flush()
                    finally:
                        os.dup2(saved, 2)
                    sink.seek(0)
                    text = sink.read().decode("utf-8", "replace")
                    prefix, other = f"{name}: ", []
                    for line in text.splitlines(keepends=True):
                        if line.startswith(prefix) and line[len(prefix) :].strip():
                            into.append(line[len(prefix) :].strip())
                        else:
                            other.append(line)
                    if other:
                        _said_again("".join(other))
        finally:
            os.close(saved)


def _said_again(text: str) -> None:
    """Write lines caught on fd 2 during a decode, not LibRaw's about the file, back through
    ``sys.stderr``: where the console entry queues its words for a thread of their own, they
    join that queue instead of waiting on the reader.

    Why not ``os.write(2, ...)``, as before: the decode runs in the main thread during a
    capture, a DSLR's frame taken with the light on; a write to a full stderr pipe whose reader
    stalled waited there, the LED lit, for as long as the reader did. Where there is no
    ``sys.stderr`` (``pythonw``), or it fails, fd 2 as before, a failure dropped."""
    stream = sys.stderr
    if stream is not None:
        try:
            stream.write(text)
            stream.flush()
            return
        except (AttributeError, OSError, ValueError):
            pass
    with suppress(OSError):
        os.write(2, text.encode("utf-8", "replace"))


def _reported(printed: list[str]) -> str:
    """LibRaw's printed lines as a clause of a refusal ("it reports: unexpected end of
    file"), or "" when it printed none."""
    if not printed:
        return ""
    words = "; ".join(dict.fromkeys(printed))  # each line once, in LibRaw's order
    return f": LibRaw reports {words[:1].lower()}{words[1:]}"


class UnsupportedRawError(RawDecodeError):
    """LibRaw does not read this file's format (a body newer than it, or no RAW at all).

    Why a class of its own: a complete file in such a format will never decode, however
    long it is waited for, unlike a file cut short (LibRaw's I/O and data errors); a watched
    folder had waited ``timeout_s`` for it to change and then advised raising
    ``stable_polls``."""


class DamagedRawError(RawDecodeError):
    """A whole RAW file whose own tags show it damaged (a CFA DNG without its CFAPattern).

    Why a class of its own: like :class:`UnsupportedRawError`, waiting will not mend it; a
    watched folder says so at once instead of waiting ``timeout_s`` for it to change."""


class MonochromeRawError(RawDecodeError):
    """A whole RAW file of a sensor without a colour filter (a monochrome camera), which no
    decode mode here turns into the session's images.

    Why a class of its own: like :class:`UnsupportedRawError`, waiting will not change it; a
    watched folder says so at once. Such a file (a LinearRaw DNG of one sample, as monochrome
    bodies write) had been refused as a damaged CFA ("copy the shot again from the camera's
    card"), advice no copy can follow, and the setting to change went unsaid."""


class RawFileMissingError(RawDecodeError):
    """The RAW file to decode is not there (``path``: the file looked for).

    Why a class of its own: a caller that decodes a copy (a watched folder's file, copied into
    the session first) words a missing copy itself, from this field: the folder's file may
    well be there, and the sentence "RAW file not found: <the copy>" had named the session's
    hidden ``raw/.incoming`` copy instead of the file the user's program saved."""


_COLOR_NAMES = "RGBG"


def exposure_stats(
    pixels: NDArray[np.uint16], white_level: int, underexposed_level: float
) -> dict[str, float]:
    """Saturated and underexposed fractions of a linear frame (pure).

    A colour pixel counts as saturated if any channel is at white, and as underexposed if its
    brightest channel is at or below ``underexposed_level × white_level``.
    """
    px = pixels if pixels.ndim == 2 else pixels.max(axis=-1)
    return {
        "saturated_fraction": float(np.mean(px >= white_level)),
        "underexposed_fraction": float(np.mean(px <= underexposed_level * white_level)),
    }


def libraw_source(path: Path | str) -> tuple[str, str | io.BytesIO]:
    """(the name LibRaw's printed lines give the file, what to hand ``rawpy.imread``) for the
    file at ``path``: its path, or its bytes where the path is not UTF-8.

    Why: rawpy hands LibRaw a ``str`` path encoded as UTF-8 (outside Windows), which a name
    that is not UTF-8 cannot be (Python holds its bytes as lone surrogates): a RAW in a folder
    named in Latin-1 (a tethering share on an old NAS, an archive unpacked with its Windows
    names) raised UnicodeEncodeError from every read. LibRaw reads the same file from memory
    (rawpy's file-object form) as it reads it from disk; other paths keep being read from
    disk, as LibRaw needs them, not whole. Raises OSError if the file cannot be read."""
    text = str(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return LIBRAW_BUFFER_NAME, io.BytesIO(Path(path).read_bytes())
    return text, text


#: Where a process's open files can be opened again by number (Linux, macOS, the BSDs):
#: an ASCII path to a file whose own path LibRaw cannot be given.
_FD_DIR = "/dev/fd"


@contextmanager
def libraw_opened(path: Path | str) -> Iterator[tuple[str, str | io.BytesIO]]:
    """:func:`libraw_source` for a read that may be repeated: a path that is not UTF-8 is
    opened here and handed to LibRaw as ``/dev/fd/N`` (ASCII, the same file), so LibRaw reads
    it from disk as it reads any other; only where there is no ``/dev/fd`` are its bytes
    read. Raises OSError if the file cannot be opened.

    Why: the capture time of a RAW in a folder whose name is not UTF-8 read the whole file
    into memory at each try (25 MB a DNG, 200 ms and 49 MB of peak memory each; a file still
    being written is tried again after each change), where LibRaw reads only its header.
    (A ``str`` of its name by ``os.fsdecode`` holds lone surrogates, which rawpy cannot
    encode: that is the UnicodeEncodeError this avoids.)"""
    text = str(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        pass
    else:
        yield text, text
        return
    if not os.path.isdir(_FD_DIR):
        yield libraw_source(path)
        return
    fd = os.open(path, os.O_RDONLY)
    try:
        yield f"{_FD_DIR}/{fd}", f"{_FD_DIR}/{fd}"
    finally:
        os.close(fd)


#: What a RAW that went before LibRaw read it is said to be.
_GONE = "RAW file not found (moved or deleted before it was read)"


def _source(
    source: Path | str | bytes,
) -> tuple[Path | None, AbstractContextManager[tuple[str, str | io.BytesIO]]]:
    """(the file read, None for bytes; the opening of what ``rawpy.imread`` is given, as the
    name LibRaw prints it by and the path or buffer) for :func:`decode_raw`'s ``source``.

    Why an opening (:func:`libraw_opened`), not the bytes: a RAW whose path is not UTF-8 had
    been read whole into memory for each decode (:func:`libraw_source`), a second copy of a
    25 MB file beside the frame decoded from it; through ``/dev/fd/N`` LibRaw reads it from
    disk, as it reads every other file."""
    if isinstance(source, bytes | bytearray):
        return None, nullcontext((LIBRAW_BUFFER_NAME, io.BytesIO(bytes(source))))
    path = Path(source)
    if not path.is_file():
        raise RawFileMissingError(path, _GONE)
    return path, libraw_opened(path)


def _iso_from_tiff(source: Path | str | bytes) -> float:
    """ISOSpeedRatings from IFD0 or the EXIF IFD of TIFF-based RAWs (DNG, NEF, CR2, ARW).

    LibRaw ignores the tag in IFD0, where minimal DNGs (ours) carry it.
    """
    try:
        import tifffile

        handle = io.BytesIO(bytes(source)) if isinstance(source, bytes | bytearray) else source
        with tifffile.TiffFile(handle) as tif:
            page = tif.pages.first
            tag = page.tags.get(34855)
            if tag is not None:
                v = tag.value
                return float(v[0] if isinstance(v, tuple | list) else v)
            exif = page.tags.get(34665)
            if exif is not None and isinstance(exif.value, dict):
                v = exif.value.get("ISOSpeedRatings")
                if v is not None:
                    return float(v[0] if isinstance(v, tuple | list) else v)
    except Exception:  # not TIFF-based (CR3, RAF...): LibRaw's value stands
        return 0.0
    return 0.0


def _pattern_name(raw: rawpy.RawPy) -> str:
    try:
        pattern = np.asarray(raw.raw_pattern)
    except NotImplementedError:  # rawpy's word for a filter code it cannot lay out
        return "unknown"
    desc = raw.color_desc.decode("ascii", "replace") if raw.color_desc else _COLOR_NAMES
    if pattern.shape != (2, 2):
        return f"{pattern.shape[0]}x{pattern.shape[1]}"
    return "".join(desc[int(i)] if int(i) < len(desc) else "?" for i in pattern.ravel())


#: sRGB (linear, D65) → CIE XYZ, IEC 61966-2-1; dcraw/LibRaw build camera → sRGB from it.
XYZ_FROM_SRGB = np.array(
    [
        [0.4124564, 0.3575761, 0.1804375],
        [0.2126729, 0.7151522, 0.0721750],
        [0.0193339, 0.1191920, 0.9503041],
    ]
)
#: LibRaw's Orientation codes (``sizes.flip``) and what they mean for the picture.
FLIP_NAMES = {0: "none", 3: "rotated 180°", 5: "rotated 90° CCW", 6: "rotated 90° CW"}
#: TIFF/EXIF Orientation tag values (TIFF 6.0 tag 274).
ORIENTATION_NAMES = {
    1: "top-left (as stored)",
    2: "mirrored horizontally",
    3: "rotated 180°",
    4: "mirrored vertically",
    5: "mirrored across the top-left to bottom-right diagonal (transposed)",
    6: "rotate 90° CW to view",
    7: "mirrored across the top-right to bottom-left diagonal (transversed)",
    8: "rotate 90° CCW to view",
}
#: The Orientation values whose picture is mirrored, not only turned: 2 and 4 across an axis,
#: 5 and 7 across a diagonal (a flip and a quarter turn). Why: a mirrored file had been said
#: to come from a rotated camera, which a user would fix by turning, never by flipping.
MIRRORED_ORIENTATIONS = frozenset({2, 4, 5, 7})


def orientation_words(tag: int | None) -> tuple[str, str]:
    """What an Orientation ``tag`` other than 1 says of a file, and what a viewer does to it:
    ("the camera was rotated", "turned upright") or, for a mirrored value,
    ("the picture is marked mirrored", "flipped back")."""
    if tag in MIRRORED_ORIENTATIONS:
        return "the picture is marked mirrored", "flipped back"
    return "the camera was rotated", "turned upright"


def srgb_from_camera(cam_xyz: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Camera RGB (white-balanced) → linear sRGB, from LibRaw's ``rgb_xyz_matrix`` (pure).

    As dcraw does: camera ← sRGB is ``cam_xyz · XYZ_FROM_SRGB``, each row normalised to sum 1
    (so a white-balanced neutral stays neutral), and inverted. ``None`` when the file carries
    no usable matrix (all zeros, as in a minimal DNG): the colour then stays camera RGB.
    """
    m = np.asarray(cam_xyz, dtype=np.float64)[:3, :3]
    if not np.any(m) or not np.all(np.isfinite(m)):
        return None
    cam_rgb = m @ XYZ_FROM_SRGB
    sums = cam_rgb.sum(axis=1, keepdims=True)
    if np.any(np.abs(sums) < 1e-9):
        return None
    cam_rgb = cam_rgb / sums
    try:
        return np.linalg.inv(cam_rgb)
    except np.linalg.LinAlgError:
        return None


def srgb_matrix(
    rgb_cam: NDArray[np.float64], cam_xyz: NDArray[np.float64]
) -> NDArray[np.float64] | None:
    """Camera RGB → linear sRGB for this file: LibRaw's ``color_matrix`` (its ``rgb_cam``,
    which for a DNG it builds from ColorMatrix1/2 and leaves ``rgb_xyz_matrix`` empty), else
    one built from ``rgb_xyz_matrix`` (:func:`srgb_from_camera`), else ``None``."""
    m = np.asarray(rgb_cam, dtype=np.float64)[:3, :3]
    if m.shape == (3, 3) and np.any(m) and np.all(np.isfinite(m)):
        return m
    return srgb_from_camera(cam_xyz)


def white_balance_multipliers(
    requested: str | tuple[float, float, float, float], camera_wb: list[float]
) -> tuple[NDArray[np.float64], str]:
    """Multipliers per colour index (R, G, B, G2) normalised to green = 1, and what they are."""
    if requested == "unity":
        return np.ones(4), "unity"
    if requested == "camera":
        wb = np.asarray(camera_wb, dtype=np.float64)
        if wb.size < 3 or wb[0] <= 0 or wb[1] <= 0 or wb[2] <= 0:
            return np.ones(4), "unity (the file has no as-shot white balance)"
        wb = np.resize(wb, 4)
        if wb[3] <= 0:
            wb[3] = wb[1]
        return wb / wb[1], "camera (as shot)"
    wb = np.asarray(requested, dtype=np.float64)
    return wb / wb[1], "user"


_K_RB = np.array([[1.0, 2.0, 1.0], [2.0, 4.0, 2.0], [1.0, 2.0, 1.0]])
_K_G = np.array([[0.0, 1.0, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 0.0]])


def bilinear_demosaic(
    values: NDArray[np.float32], channel: NDArray[np.intp]
) -> NDArray[np.float32]:
    """Bilinear demosaic by normalised convolution (pure): each photosite keeps its own value,
    a missing colour is the weighted mean of that colour's neighbours (4-neighbours for green,
    the 3×3 ring for red and blue). Borders use only the neighbours that exist."""
    # scipy.ndimage takes 0.2 s to import: only a decode needs it, not every importer of this
    # module (``rti-rig plan`` asks folder_watch whether a preview is a RAW file)
    from scipy.ndimage import correlate

    h, w = values.shape
    out = np.empty((h, w, 3), dtype=np.float32)
    for c in range(3):
        mask = (channel == c).astype(np.float32)
        k = _K_G if c == 1 else _K_RB
        num = correlate(values * mask, k, mode="constant")
        den = correlate(mask, k, mode="constant")
        with np.errstate(invalid="ignore", divide="ignore"):
            interp = np.where(den > 0, num / np.maximum(den, 1e-12), 0.0)
        out[..., c] = np.where(mask > 0, values, interp)
    return out


def half_size(values: NDArray[np.float32], channel: NDArray[np.intp]) -> NDArray[np.float32]:
    """2×2 super-pixels (pure): red, the mean of the two greens, blue; no interpolation."""
    h, w = (values.shape[0] // 2) * 2, (values.shape[1] // 2) * 2
    v = (
        values[:h, :w]
        .reshape(h // 2, 2, w // 2, 2)
        .transpose(0, 2, 1, 3)
        .reshape(h // 2, w // 2, 4)
    )
    ch = channel[:2, :2].ravel()
    out = np.empty((h // 2, w // 2, 3), dtype=np.float32)
    for c in range(3):
        sites = np.flatnonzero(ch == c)
        if sites.size == 0:
            raise ValueError("the CFA's 2×2 tile lacks a colour: half-size needs a Bayer pattern")
        out[..., c] = v[..., sites].mean(axis=-1)
    return out


def half_size_mask(mask: NDArray[np.bool_], h: int, w: int) -> NDArray[np.bool_]:
    """The photosite ``mask`` on LibRaw's h×w half-size output: a super-pixel is marked when
    any of its 2×2 photosites is. A sensor with an odd visible size has a last, incomplete
    row or column of super-pixels; the mask is padded (unmarked) to fit instead of failing."""
    full = np.zeros((2 * h, 2 * w), dtype=bool)
    rows, cols = min(mask.shape[0], 2 * h), min(mask.shape[1], 2 * w)
    full[:rows, :cols] = mask[:rows, :cols]
    return full.reshape(h, 2, w, 2).any(axis=(1, 3))


def _dilate(mask: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """3×3 dilation: a demosaiced pixel draws on its neighbours' photosites."""
    p = np.pad(mask, 1)
    out = np.zeros_like(mask)
    h, w = mask.shape
    for dy in range(3):
        for dx in range(3):
            out |= p[dy : dy + h, dx : dx + w]
    return out


#: OpenCV's Bayer conversion codes, by our CFA name (OpenCV names a pattern by the second row's
#: second and third pixels, hence the apparent swap; checked for all four patterns in the tests).
_CV_BAYER = {
    "RGGB": cv2.COLOR_BayerBG2RGB,
    "BGGR": cv2.COLOR_BayerRG2RGB,
    "GRBG": cv2.COLOR_BayerGB2RGB,
    "GBRG": cv2.COLOR_BayerGR2RGB,
}


def _colour(
    raw: NDArray[np.uint16],
    colors: NDArray[np.integer],
    black_pc: NDArray[np.int64],
    white: int,
    wb: NDArray[np.float64],
    rgb_index: NDArray[np.intp],
    mode: str,
) -> NDArray[np.float32]:
    """Black-corrected (per site, exactly), white-balanced linear RGB, full or half size.

    A 2×2 Bayer sensor (the usual case) is handled site by site on strided views, and
    demosaiced with OpenCV's bilinear Bayer conversion; any other CFA goes through the
    per-photosite path and :func:`bilinear_demosaic`.
    """
    h, w = raw.shape
    tile = colors[:2, :2] if colors.shape[0] >= 2 and colors.shape[1] >= 2 else None
    names = "".join("RGB"[rgb_index[int(c)]] for c in tile.ravel()) if tile is not None else ""
    bayer = (
        names in _CV_BAYER
        and h % 2 == 0
        and w % 2 == 0
        and np.array_equal(colors, np.tile(tile, (h // 2, w // 2)))
    )
    gain = wb / (white - black_pc)  # per colour index: (raw − black_c) × gain_c
    if not bayer:
        norm = (raw.astype(np.float32) - black_pc[colors].astype(np.float32)) * gain.astype(
            np.float32
        )[colors]
        norm = np.clip(norm, 0.0, wb.astype(np.float32)[colors])
        channel = rgb_index[colors]
        return half_size(norm, channel) if mode == "half" else bilinear_demosaic(norm, channel)
    sites = {}
    for dy in (0, 1):
        for dx in (0, 1):
            c = int(tile[dy, dx])
            v = raw[dy::2, dx::2].astype(np.float32)
            v -= np.float32(black_pc[c])
            v *= np.float32(gain[c])
            np.clip(v, 0.0, np.float32(wb[c]), out=v)
            sites[(dy, dx)] = (rgb_index[c], v)
    if mode == "half":
        out = np.empty((h // 2, w // 2, 3), dtype=np.float32)
        greens = [v for ch, v in sites.values() if ch == 1]
        for ch, v in sites.values():
            if ch != 1:
                out[..., ch] = v
        out[..., 1] = (greens[0] + greens[1]) * np.float32(0.5)
        return out
    top = float(max(wb.max(), 1.0))  # white-balanced values reach up to the largest multiplier
    plane = np.empty((h, w), dtype=np.float32)
    for (dy, dx), (_, v) in sites.items():
        plane[dy::2, dx::2] = v
    plane *= np.float32(65535.0 / top)
    mosaic = np.rint(plane, out=plane).astype(np.uint16)
    rgb = cv2.cvtColor(mosaic, _CV_BAYER[names]).astype(np.float32)
    rgb *= np.float32(top / 65535.0)
    return rgb


def _orientation_tag(source: Path | str | bytes) -> int | None:
    """The TIFF/EXIF Orientation tag (274) of IFD0 of a TIFF-based RAW, if it has one."""
    try:
        import tifffile

        handle = io.BytesIO(bytes(source)) if isinstance(source, bytes | bytearray) else source
        with tifffile.TiffFile(handle) as tif:
            tag = tif.pages.first.tags.get(274)
            return None if tag is None else int(tag.value)
    except Exception:  # not TIFF-based: LibRaw's flip stands alone
        return None


def orientation_record(flip: int, tag: int | None) -> dict[str, Any]:
    """What the file says of the camera's orientation, and that the pixels are not rotated."""
    rotated = flip not in (0,) or (tag is not None and tag != 1)
    return {
        "applied": False,
        "pixels": "sensor orientation (as stored in the RAW; the camera's JPEG previews and "
        "the rti-rig JPEGs agree)",
        "libraw_flip": int(flip),
        "flip_meaning": FLIP_NAMES.get(int(flip), f"code {flip}"),
        "orientation_tag": tag,
        "orientation_tag_meaning": None if tag is None else ORIENTATION_NAMES.get(tag),
        "camera_rotated": bool(rotated),
    }


def decode_raw(
    source: Path | str | bytes,
    settings: RawDecodeSettings | None = None,
    dark: Frame | None = None,
    timestamp_s: float | None = None,
) -> Frame:
    """Decode a RAW file (path or bytes) into a linear ``Frame``.

    Saturation is detected on the raw values *before* any processing (a saturated photosite
    marks its output pixel saturated: pinned at ``white_level``), so it survives dark
    subtraction and white balance. ``exposure_s`` and ``gain`` (ISO) come from the file's
    metadata (0.0 when absent); callers that set the exposure themselves record theirs too.
    ``metadata["decode"]`` is the provenance the session journals for each image.
    """
    settings = settings or RawDecodeSettings()
    read, opening = _source(source)
    printed: list[str] = []  # LibRaw's own lines, kept off the terminal (libraw_printed)
    blind = None if read is None else read_blind(read)
    if blind is not None:  # before LibRaw, which decodes such a file without a word
        raise DamagedRawError(
            read,
            f"it names itself a DNG, but {blind}. The file is damaged: copy the shot again "
            "from the camera's card",
        )
    try:
        with (
            opening as (printed_name, handle),
            libraw_printed(printed_name, printed),
            rawpy.imread(handle) as raw,
        ):
            raw_vis = np.array(raw.raw_image_visible)  # uint16 copy out of LibRaw memory
            colors = np.array(raw.raw_colors_visible)
            black_pc = np.asarray(raw.black_level_per_channel, dtype=np.int64)
            white = int(raw.white_level)
            pattern = _pattern_name(raw)
            desc = raw.color_desc.decode("ascii", "replace") if raw.color_desc else _COLOR_NAMES
            camera_wb = list(raw.camera_whitebalance)
            cam_xyz = np.array(raw.rgb_xyz_matrix)
            rgb_cam = np.array(raw.color_matrix)
            flip = int(raw.sizes.flip)
            per_channel_white = getattr(raw, "camera_white_level_per_channel", None)
            white_per_channel = (
                None
                if per_channel_white is None or not any(per_channel_white)
                else [int(v) for v in per_channel_white]
            )
            other = raw.other
            colours_sensed = int(raw.num_colors)
    except FileNotFoundError:  # gone between the check and its opening
        if read is None:
            raise
        raise RawFileMissingError(read, _GONE) from None
    except rawpy.LibRawFileUnsupportedError as exc:
        # a body newer than the bundled LibRaw (a new Canon CR3 or Fujifilm RAF, say) gives
        # this, a truncated download a data or I/O error: "is it a complete download?" had
        # sent the owner of a new camera looking for a cable fault. LibRaw says the same of a
        # DNG whose tags are damaged, for which "Update rawpy" had been the advice: a DNG's
        # own tags tell which where they can (dng_tags), and both are said where they cannot
        said = libraw_words(exc)
        libraw = libraw_named()
        dng = None if read is None else dng_refusal(read)
        problem = (
            f"{libraw} refuses it as of a format it does not read ({said}){_reported(printed)}"
            f", but it names itself a DNG, and {dng}"
            if dng is not None
            else f"{libraw} does not read this file's format ({said}){_reported(printed)}: "
            "a camera newer than this LibRaw, or a file that is no RAW or is damaged. "
            f"Update rawpy ({pip_upgrade('rawpy')}), or shoot a format it reads (DNG where the "
            "camera offers it, or convert the files with a DNG converter and watch a "
            "folder of DNGs); if no other program opens the file either, it is damaged: "
            "copy it again from the camera's card"
        )
        raise UnsupportedRawError(
            read,
            problem,
            libraw_error=type(exc).__name__,
            libraw_said=said,
            libraw_printed=tuple(printed),
        ) from exc
    except NotImplementedError as exc:  # rawpy: a CFA layout it cannot lay out
        raise DamagedRawError(
            read,
            f"rawpy cannot lay out its colour filter array ({exc}): its CFA tags are damaged, "
            "or it is a sensor layout this rawpy does not know. Copy the shot again from the "
            f"camera's card; if another program opens it, update rawpy ({pip_upgrade('rawpy')})",
        ) from exc
    except rawpy.LibRawError as exc:
        said = libraw_words(exc)
        raise RawDecodeError(
            read,
            f"LibRaw cannot decode this file ({type(exc).__name__}: {said})"
            f"{_reported(printed)}; is it a complete RAW/DNG download?",
            libraw_error=type(exc).__name__,
            libraw_said=said,
            libraw_printed=tuple(printed),
        ) from exc
    if raw_vis.ndim != 2:
        raise RawDecodeError(read, "not a single-plane CFA RAW")
    if colours_sensed == 1:  # LibRaw: one colour, no CFA (its colour codes then mean nothing)
        raise MonochromeRawError(read, _monochrome_refusal(settings.mode))
    if white <= int(black_pc.max()):
        raise RawDecodeError(
            read, f"white level {white} is not above the black levels {black_pc.tolist()}"
        )
    cfa = _cfa_refusal(colors, desc, settings.mode)
    if cfa is not None:
        raise RawDecodeError(read, cfa)
    # Uniform black (the usual case) stays scalar: uint16 arithmetic, no index arrays.
    uniform = bool(np.all(black_pc == black_pc[0]))
    black: int | NDArray[np.int64] = int(black_pc[0]) if uniform else black_pc[colors]
    threshold = black + np.floor(settings.saturation_level * (white - black))
    saturated = raw_vis >= threshold
    wb, wb_source = white_balance_multipliers(settings.white_balance, camera_wb)
    to_srgb = srgb_matrix(rgb_cam, cam_xyz) if settings.output_color == "srgb" else None
    if settings.mode == "mosaic":
        white_level = int(white - black_pc.max())
        if uniform:
            pixels = np.clip(raw_vis, black, black + white_level) - np.uint16(black)
        else:
            pixels = np.clip(raw_vis.astype(np.int64) - black, 0, white_level)
        pixels = pixels.astype(np.uint16, copy=False)
        pixels[saturated] = white_level
        color_space = "none (CFA mosaic: one colour per pixel)"
    else:
        rgb_index = np.array([_rgb_channel(desc, int(i)) for i in range(4)], dtype=np.intp)
        try:
            rgb = _colour(raw_vis, colors, black_pc, white, wb, rgb_index, settings.mode)
        except ValueError as exc:
            raise RawDecodeError(read, str(exc)) from exc
        if to_srgb is not None:
            rgb = cv2.transform(rgb, to_srgb.astype(np.float32))
        white_level = 65535
        np.clip(rgb, 0.0, 1.0, out=rgb)
        rgb *= white_level
        pixels = np.rint(rgb, out=rgb).astype(np.uint16)
        h, w = pixels.shape[:2]
        sat = half_size_mask(saturated, h, w) if settings.mode == "half" else _dilate(saturated)
        pixels[sat[:h, :w]] = white_level
        if to_srgb is not None:
            color_space = "linear sRGB (IEC 61966-2-1 primaries, D65) from the file's matrix"
        elif settings.output_color == "srgb":
            color_space = "camera RGB (the file has no colour matrix, so none was applied)"
        else:
            color_space = "camera RGB"
    iso = float(other.iso_speed) or _iso_from_tiff(source)
    exposure = float(other.shutter_speed)
    if timestamp_s is None:
        timestamp_s = read.stat().st_mtime if read is not None else 0.0
    source_file = None if read is None else str(read)
    orientation = orientation_record(flip, _orientation_tag(source))
    decode = {
        "mode": settings.mode,
        "content": "cfa-mosaic" if settings.mode == "mosaic" else "rgb",
        "cfa_pattern": pattern,
        "black_level_per_channel": _per_channel(black_pc, desc),
        "black_level_by_color_index": [int(b) for b in black_pc],
        "black_correction": "exact per CFA site: (raw − black_c) / (white − black_c)",
        "white_level": white,
        "white_level_per_channel": white_per_channel,
        "white_balance": wb_source if settings.mode != "mosaic" else "none (mosaic)",
        "white_balance_multipliers": None
        if settings.mode == "mosaic"
        else [round(float(x), 6) for x in wb[:3]],
        "color_space": color_space,
        "srgb_from_camera": None if to_srgb is None else np.round(to_srgb, 6).tolist(),
        "source_file": source_file,
        "orientation": orientation,
        "decoder": f"rti-rig raw_decode (LibRaw {rawpy.libraw_version} for unpacking)"
        if hasattr(rawpy, "libraw_version")
        else "rti-rig raw_decode (LibRaw for unpacking)",
    }
    notices = []
    if orientation["camera_rotated"]:
        tag = orientation["orientation_tag"]
        meaning = orientation["orientation_tag_meaning"] or orientation["flip_meaning"]
        happened, undone = orientation_words(tag)
        notices.append(
            f"{happened} (Orientation tag {tag}: {meaning}): rti-rig keeps "
            "sensor orientation, as the camera's RAW data and JPEG previews are stored, so "
            f"these images are not {undone}; the .lp light directions are in the same "
            "(sensor) frame, so fitting is unaffected (docs/cameras.md)"
        )
    if printed:
        # LibRaw went on past a data error it printed (kept off the terminal): the image is
        # recorded, and what LibRaw said of it is kept with it rather than lost
        decode["libraw_reported"] = list(dict.fromkeys(printed))
        notices.append(
            f"LibRaw reported {'; '.join(decode['libraw_reported'])} while decoding this "
            "file, and decoded it anyway: check the image for damage"
        )
    metadata: dict[str, Any] = {
        "source_file": source_file,
        "decode_mode": settings.mode,
        "white_balance": settings.white_balance,
        "output_color": settings.output_color if settings.mode != "mosaic" else "raw",
        "cfa_pattern": pattern,
        "raw_black_level": [int(b) for b in black_pc],
        "raw_white_level": white,
        "exposure_s_from_file": exposure or None,
        "iso_from_file": iso or None,
        "aperture_from_file": float(other.aperture) or None,
        "dark_subtracted": False,
        "decode": decode,
        "notices": notices,
    }
    metadata.update(exposure_stats(pixels, white_level, settings.underexposed_level))
    frame = Frame(
        pixels=pixels,
        exposure_s=exposure,
        gain=iso,
        white_level=white_level,
        timestamp_s=float(timestamp_s),
        metadata=metadata,
    )
    if dark is not None:
        frame = subtract_dark(frame, dark, settings.underexposed_level)
    return frame


def _monochrome_refusal(mode: str) -> str:
    """What to say of a monochrome sensor's RAW decoded in ``mode``, naming what to change.

    Why refused in every mode: ``"demosaic"`` and ``"half"`` make colour images of a colour
    filter's photosites, and a session's images are of one kind (colour or grey) fixed by its
    first; ``"mosaic"`` labels its images CFA mosaics, which ``rti-rig fit`` refuses and
    export-lp warns of, though a monochrome sensor's are grey pictures. A grey TIFF is what
    the session takes as a grey picture, and only a folder-watch camera reads TIFFs: the
    advice names that driver, as a gphoto2 camera's config has no ``patterns`` key (it had
    told a gphoto2 rig to set one in its ``[camera.device]``, which its config refuses)."""
    kind = (
        "a grey picture, while this camera is set to make colour images "
        f'([camera.device.decode] mode = "{mode}"), and a session\'s images are all of one '
        "kind"
        if mode != "mosaic"
        else 'a grey picture, which mode = "mosaic" would label a colour-filter mosaic (one '
        "colour per pixel, refused by rti-rig fit)"
    )
    return (
        "it is a monochrome sensor's file (LibRaw reads one colour and no colour filter array): "
        f"{kind}. No RAW decode mode here takes it: save the shots as 16-bit grey TIFFs (the "
        "camera's program or a RAW converter) and watch those with a folder-watch camera "
        '(patterns = ["*.tif"] in its [camera.device]), which make a grey session, or shoot '
        "with a colour camera"
    )


def _cfa_refusal(colors: NDArray[np.integer], desc: str, mode: str) -> str | None:
    """Why the photosite colours LibRaw gives (``colors``, indices into ``desc``) cannot make
    the image ``mode`` asks for, or None when they can.

    Why: a DNG whose CFAPattern tag is lost or damaged still decodes: LibRaw fills the
    pattern from what it has (every photosite red, or colour codes past its four), and the
    file had gone into the session as a picture of one colour, or stopped the run with an
    IndexError from the colour step. A colour image needs red, green and blue photosites.
    A sensor without a colour filter is sent to grey TIFFs, as ``_monochrome_refusal`` does,
    not to ``mode = "mosaic"``: that labels its images CFA mosaics, which ``rti-rig fit``
    refuses, so the session could never be fitted."""
    codes = np.unique(colors)
    if codes.size and int(codes.max()) >= 4:
        return (
            f"LibRaw gives its photosites colour codes up to {int(codes.max())}, beyond the "
            "four a colour filter array has: its CFA tags (CFAPattern, CFARepeatPatternDim) "
            "are damaged or lost. Copy the shot again from the camera's card"
        )
    if mode == "mosaic":
        return None
    found = {_rgb_channel(desc, int(c)) for c in codes}
    if found == {0, 1, 2}:
        return None
    named = "".join("RGB"[c] for c in sorted(found)) or "none"
    return (
        f"its colour filter array as LibRaw reads it has photosites of {named} only, so no "
        "colour picture can be made of it: its CFA tags (CFAPattern, CFARepeatPatternDim) "
        "are damaged or lost (copy the shot again from the camera's card), or its sensor "
        "has no colour filter (a monochrome camera, whose shots no RAW decode mode here takes: "
        'mode = "mosaic" would label them colour-filter mosaics, which rti-rig fit refuses). '
        "For a monochrome camera, save the shots as 16-bit grey TIFFs (the camera's program "
        'or a RAW converter) and watch those (patterns = ["*.tif"] in [camera.device]), '
        "which make a grey session"
    )


def _rgb_channel(desc: str, index: int) -> int:
    """RGB plane (0, 1, 2) of LibRaw colour index ``index`` (``color_desc`` 'RGBG')."""
    letter = desc[index] if index < len(desc) else "G"
    return {"R": 0, "G": 1, "B": 2}.get(letter, 1)


def _per_channel(black_pc: NDArray[np.int64], desc: str) -> dict[str, int]:
    """{colour name: black} for LibRaw's colour indices, the second green named 'G2'."""
    out: dict[str, int] = {}
    for i, b in enumerate(black_pc[: len(desc)]):
        key = desc[i] if desc[i] not in out else f"{desc[i]}2"
        out[key] = int(b)
    return out


def subtract_dark(frame: Frame, dark: Frame, underexposed_level: float = 0.001) -> Frame:
    """Subtract a dark frame (same decode settings, same exposure) from a linear frame (pure).

    Saturated pixels stay pinned at the white level: a clipped pixel minus a dark is *not* a
    valid measurement, and keeping it at white keeps it flagged.
    """
    if dark.pixels.shape != frame.pixels.shape:
        raise CaptureError(
            DECODER,
            f"dark frame shape {dark.pixels.shape} does not match image {frame.pixels.shape}; "
            "decode the dark with the same settings (mode) as the images",
            "dark",
        )
    if dark.white_level != frame.white_level:
        raise CaptureError(
            DECODER,
            f"dark frame white level {dark.white_level} differs from the image's "
            f"{frame.white_level}; decode both with the same settings",
            "dark",
        )
    if frame.exposure_s > 0 and dark.exposure_s > 0:
        rel = abs(dark.exposure_s - frame.exposure_s) / frame.exposure_s
        if rel > 0.01:
            raise CaptureError(
                DECODER,
                f"dark frame exposure {dark.exposure_s:g} s differs from the image's "
                f"{frame.exposure_s:g} s; take darks at the session exposure",
                "dark",
            )
    px = frame.pixels.astype(np.int64)
    out = np.clip(px - dark.pixels.astype(np.int64), 0, frame.white_level)
    out[px >= frame.white_level] = frame.white_level
    pixels = out.astype(np.uint16)
    metadata = dict(frame.metadata)
    metadata["dark_subtracted"] = True
    metadata["dark_file"] = dark.metadata.get("source_file")
    metadata.update(exposure_stats(pixels, frame.white_level, underexposed_level))
    return Frame(
        pixels=pixels,
        exposure_s=frame.exposure_s,
        gain=frame.gain,
        white_level=frame.white_level,
        timestamp_s=frame.timestamp_s,
        metadata=metadata,
    )


def average_frames(frames: list[Frame]) -> Frame:
    """Mean of several frames (a master dark), rounded to uint16 (pure)."""
    if not frames:
        raise ValueError("average_frames needs at least one frame")
    first = frames[0]
    for f in frames[1:]:
        if f.pixels.shape != first.pixels.shape or f.white_level != first.white_level:
            raise ValueError("frames to average must share shape and white level")
    mean = np.mean([f.pixels.astype(np.float64) for f in frames], axis=0)
    metadata = dict(first.metadata)
    metadata["averaged_from"] = [f.metadata.get("source_file") for f in frames]
    return Frame(
        pixels=np.rint(mean).astype(np.uint16),
        exposure_s=first.exposure_s,
        gain=first.gain,
        white_level=first.white_level,
        timestamp_s=first.timestamp_s,
        metadata=metadata,
    )
