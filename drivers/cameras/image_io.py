"""Non-RAW pixels (UVC frames, 16-bit TIFF/PNG) to linear uint16 data.

Why: the RAW path has LibRaw; everything else arrives as 8- or 16-bit arrays from OpenCV or
tifffile and needs one honest conversion. 16-bit data is taken as linear (Y16 sensors, linear
TIFFs). 8-bit data is gamma-encoded on nearly every camera, so it is only accepted through an
explicit response curve: ``"srgb"`` (inverse sRGB) or ``"linear"`` (the user asserts it is).
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from rti_rig.core import opencv_files
from rti_rig.core.errors import CaptureError
from rti_rig.core.image_files import (
    SeveralFullSizeImages,
    opencv_as_stored,
    tiff_is_planar,
    tiff_main_image,
    tiff_one_image,
    tiff_samples_last,
)
from rti_rig.core.shell_words import shown_path
from rti_rig.drivers.cameras.tiff_ifd import header_size
from rti_rig.drivers.cameras.tiff_structure import (
    COMPLETE_TIFF_ADVICE,
    SAVE_READABLE,
    unread_compression,
)

Response = Literal["linear", "srgb"]


def _srgb_to_linear_lut() -> NDArray[np.uint16]:
    v = np.arange(256, dtype=np.float64) / 255.0
    lin = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    return np.rint(lin * 65535).astype(np.uint16)


_SRGB_LUT = _srgb_to_linear_lut()


def to_linear_uint16(
    image: NDArray,
    response: Response,
    black_level: int = 0,
    white_level: int = 65535,
    *,
    order: Literal["bgr", "rgb"],
) -> tuple[NDArray[np.uint16], int]:
    """Return ``(pixels, white_level)``: linear uint16 at full scale (white 65535), RGB order
    for colour input (pure).

    16-bit data of a sensor whose range ends lower (``white_level`` − ``black_level``: a 12-bit
    sensor's 4095) is scaled up to 65535, as the RAW path's demosaiced output is: a session's
    linear TIFF carries no white level, so every reader of it (``rti-rig fit``, its QA, relight)
    takes 65535 as white; unscaled, saturation went unseen there and the exports came out 16×
    too dark in linear terms. The scaling maps distinct codes to distinct codes: nothing is lost.

    ``order`` is the channel order of ``image``: OpenCV delivers BGR (a UVC frame,
    ``cv2.imread``), tifffile RGB as stored. It is required because a wrong guess swaps red
    and blue in every image of a session without an error (a watched folder of TIFFs did).
    """
    img = np.asarray(image)
    if img.ndim == 3 and img.shape[2] == 1:
        img = img[..., 0]
    if img.ndim == 3 and img.shape[2] == 4:
        img = img[..., :3]
    if img.ndim == 3 and img.shape[2] == 3:
        if order == "bgr":
            img = img[..., ::-1]
    elif img.ndim != 2:
        raise ValueError(f"expected an H×W or H×W×3 image, got shape {img.shape}")
    if img.dtype == np.uint16:
        wl = white_level - black_level
        if wl <= 0:
            raise ValueError(f"white_level {white_level} must exceed black_level {black_level}")
        px = np.clip(img.astype(np.int64) - black_level, 0, wl)
        if wl != 65535:
            px = (px * 65535 + wl // 2) // wl  # rounded, exact in integers
        return np.ascontiguousarray(px.astype(np.uint16)), 65535
    if img.dtype == np.uint8:
        if response == "srgb":
            return np.ascontiguousarray(_SRGB_LUT[img]), 65535
        return np.ascontiguousarray(img.astype(np.uint16) * 257), 65535
    raise ValueError(f"unsupported pixel type {img.dtype}; expected uint8 or uint16")


class ImageReadError(CaptureError):
    """An image file that would not read, with what is known as fields: ``path`` (the file
    read), ``reason`` (the reader's own words), ``is_tiff``, ``no_pixels`` (it read, as an
    image of no pixels: a TIFF whose IFD is not written yet or is damaged, which tifffile
    reads past, logging; only its bytes tell which), ``compression`` (the name of a TIFF
    compression the reader does not decode, None otherwise) and ``contradicts`` (its own tags
    contradict each other: :func:`tiff_contradiction`; a damaged file, unless its bytes are
    not all written yet) and ``several`` (a whole TIFF of two or more full-size images, which
    one is the photograph not known: no wait or copy mends it, saving one image does) and
    ``thumbnail_only`` (a TIFF whose every image is marked reduced-resolution: a thumbnail
    with the full image not written after it yet, as a libtiff writer leaves it mid-file).

    Why fields: a caller that words the failure its own way (a watched folder naming the
    folder's file, not the session's copy it read, and whether waiting can help) had cut this
    function's sentence at a fixed phrase; rewording it would have broken that caller's."""

    def __init__(
        self,
        device: str,
        path: Path,
        reason: str,
        *,
        is_tiff: bool,
        no_pixels: bool = False,
        compression: str | None = None,
        contradicts: bool = False,
        several: bool = False,
        thumbnail_only: bool = False,
    ) -> None:
        self.path = path
        self.reason = reason
        self.is_tiff = is_tiff
        self.no_pixels = no_pixels
        self.compression = compression
        self.contradicts = contradicts
        self.several = several
        self.thumbnail_only = thumbnail_only
        advice = (
            f": {SAVE_READABLE}"
            if compression
            else f": {COMPLETE_TIFF_ADVICE}"
            if is_tiff and not several
            else ""
        )
        detail = f" ({reason})" if reason else ""
        super().__init__(
            device, f"cannot read image file {shown_path(path)}{detail}{advice}", "read"
        )


def _cut_within_header(path: Path) -> str | None:
    """Why ``path`` (named as a TIFF) ends before its header does, or None when its header is
    all there (or it begins as no TIFF, or cannot be opened: tifffile then says so).

    Why: a TIFF still being written may hold only its first bytes; tifffile then fails
    unpacking them with a bare ``struct.error``, which had escaped a capture as a traceback."""
    try:
        with path.open("rb") as f:
            head = f.read(16)
    except OSError:
        return None
    need = header_size(head) if len(head) >= 4 else 8
    if need is None or len(head) >= need:
        return None
    return f"it ends within its {need}-byte header: {len(head)} bytes written"


#: PhotometricInterpretation codes whose pixels are colour, and how many samples each takes
#: (TIFF 6.0: RGB 2, YCbCr 6, CIELab 8; ICCLab 9 and ITULab 10 of the TIFF/IT and Adobe notes)
COLOUR_SAMPLES = {
    2: ("RGB", 3),
    6: ("YCbCr", 3),
    8: ("CIELab", 3),
    9: ("ICCLab", 3),
    10: ("ITULab", 3),
}


def tiff_contradiction(page: Any) -> str | None:
    """Why ``page`` (a tifffile page) contradicts itself, as a phrase ("its
    PhotometricInterpretation says RGB …"), or None when its tags agree.

    Why: a TIFF whose SamplesPerPixel tag is lost (one tag number damaged) is read by tifffile
    with TIFF's default of one sample, silently: an RGB picture came into a session as a
    single-channel image of the same size, the colour the file itself declares gone. Its
    PhotometricInterpretation and its BitsPerSample (one value per sample) still tell."""
    tags = page.tags
    photometric = tags.get("PhotometricInterpretation")
    samples_tag = tags.get("SamplesPerPixel")
    samples = int(samples_tag.value) if samples_tag is not None else 1
    said = f"is {samples}" if samples_tag is not None else "tag is missing, so TIFF's default, 1,"
    if photometric is not None:
        colour = COLOUR_SAMPLES.get(int(photometric.value))
        if colour is not None and samples < colour[1]:
            return (
                f"its PhotometricInterpretation says {colour[0]}, which takes {colour[1]} "
                f"samples per pixel, but its SamplesPerPixel {said} applies: read as it stands "
                "it would be a one-channel image, not the colour picture it says it is"
            )
    bits = tags.get("BitsPerSample")
    if bits is not None and bits.count > 1 and bits.count != samples:
        return (
            f"its BitsPerSample gives {bits.count} values (one per sample) but its "
            f"SamplesPerPixel {said}{' applies' if samples_tag is None else ''}"
        )
    return None


#: TIFF ExtraSamples values (TIFF 6.0, section 18): what an extra sample per pixel is
EXTRA_SAMPLE_KINDS = {0: "unspecified", 1: "associated", 2: "unassociated"}


def tiff_extra_samples(path: Path) -> tuple[str, ...]:
    """What the extra samples of a TIFF's full-resolution image are, by its ExtraSamples tag
    (``"associated"`` alpha, i.e. premultiplied; ``"unassociated"`` alpha; ``"unspecified"``),
    one word per extra sample; empty for no extra samples, another format, or a file that
    will not parse (its reader says why).

    Why: a tethering program may save grey + alpha or RGBA. Unassociated alpha carries no
    light and can be dropped; premultiplied alpha has already scaled every colour sample by
    it, so the pixels left once it is dropped are not what the camera measured."""
    if path.suffix.lower() not in (".tif", ".tiff"):
        return ()
    import tifffile

    try:
        with tifffile.TiffFile(path) as tif:
            page = tiff_main_image(tif).keyframe
            values = tuple(int(v) for v in (getattr(page, "extrasamples", ()) or ()))
    except Exception:  # tifffile raises many kinds; read_image_file names the problem
        return ()
    return tuple(EXTRA_SAMPLE_KINDS.get(v, "unspecified") for v in values)


def read_image_file(path: Path, device: str) -> NDArray:
    """Read a non-RAW image file with its bit depth kept, colour in **RGB** order whatever the
    format (OpenCV decodes PNG/JPEG as BGR, tifffile TIFF as RGB: one order for callers), and
    samples last, (H, W) or (H, W, samples), whatever a TIFF's planar configuration.

    Raises :class:`ImageReadError` for a file that will not read."""
    suffix = path.suffix.lower()
    if suffix in (".tif", ".tiff"):
        import tifffile  # on a TIFF only: `rti-rig plan` imports this module for any preview

        cut = _cut_within_header(path)
        if cut is not None:
            # tifffile unpacks a header cut short as itself: a struct.error had escaped
            raise ImageReadError(device, path, cut, is_tiff=True)
        try:
            with tifffile.TiffFile(path) as tif:
                # the full-resolution image, not IFD0: a camera or tethering program may put
                # a thumbnail first (it had been taken as the shot, at thumbnail size)
                main = tiff_one_image(tif) if tif.series else None
                image = main.asarray() if main is not None else tif.asarray()
                page = main.keyframe if main is not None else None
                if page is None and len(tif.pages):
                    page = tif.pages[0]
                contradiction = tiff_contradiction(page) if page is not None else None
                # every image a thumbnail (NewSubfileType bit 0): no shot yet, never taken as
                # one (a thumbnail-first file a writer paused in had gone in at 16x16)
                reduced = page is not None and int(getattr(page, "subfiletype", 0) or 0) & 1
        except SeveralFullSizeImages as exc:
            raise ImageReadError(device, path, str(exc), is_tiff=True, several=True) from exc
        except (ValueError, OSError, RuntimeError, struct.error) as exc:
            # a TIFF cut short or not a TIFF at all (tifffile raises ValueError, TiffFileError
            # among them), or compressed data that will not decompress (imagecodecs' errors
            # are RuntimeErrors): it had escaped as itself, a Python traceback mid-session
            compression = unread_compression(path, str(exc))
            if compression is not None:
                reason = f"it is compressed as {compression}, which the TIFF reader does not decode"
                raise ImageReadError(
                    device, path, reason, is_tiff=True, compression=compression
                ) from exc
            raise ImageReadError(device, path, str(exc), is_tiff=True) from exc
        if image.size == 0:  # a damaged IFD tifffile reads past, logging, as no pixels
            raise ImageReadError(device, path, "it holds no pixels", is_tiff=True, no_pixels=True)
        if reduced:
            raise ImageReadError(
                device,
                path,
                "it holds only a reduced-resolution image (a thumbnail, NewSubfileType 1), "
                f"{image.shape[1]}x{image.shape[0]}, not the full-size image",
                is_tiff=True,
                thumbnail_only=True,
            )
        if contradiction is not None:  # never taken as the other image it reads as
            raise ImageReadError(device, path, contradiction, is_tiff=True, contradicts=True)
        # a planar TIFF (Photoshop's "Per Channel") decodes samples first, (3, H, W): it had
        # been refused mid-run as an image of the wrong shape, as the core reader puts it right
        return tiff_samples_last(image, page is not None and tiff_is_planar(page))
    img = opencv_files.imread(path)
    if img is None:
        raise ImageReadError(device, path, "", is_tiff=False)
    return opencv_as_stored(img, path)  # grey + alpha as grey, BGR(A) -> RGB, alpha dropped
