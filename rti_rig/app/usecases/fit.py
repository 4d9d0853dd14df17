"""`rti-rig fit`: normals, albedo, relightable files and a QA verdict from a finished session.

Input: a session folder (``lights.lp`` and ``linear/*.tif`` 16-bit linear, as
:mod:`rti_rig.runtime.session` writes it) or any ``.lp`` with its images beside it (16-bit TIFF
used as linear; 8-bit JPEG/PNG decoded from sRGB; a colour file that says Adobe RGB, ProPhoto or
Display P3, or a 16-bit sRGB-encoded one, converted to linear sRGB as a session's frames are,
:mod:`rti_rig.drivers.cameras.colour_convert`). Uncompressed TIFFs are read a band of rows
at a time in place (:class:`rti_rig.core.tiff_rows.TiffRows`); compressed ones and JPEG/PNG are
decoded once into a temporary file and read back by rows (:class:`rti_rig.core.raw_rows.RawRows`).
The stack is never held, as floats or otherwise; one streamed pass computes every output.
"""

from __future__ import annotations

import contextlib
import errno
import html
import json
import math
import os
import threading
import time
import warnings
from collections.abc import Callable, Collection, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from threadpoolctl import threadpool_limits

from rti_rig.app.usecases.fit_bands import BandFit, BandPlan, fit_band, fit_warnings
from rti_rig.app.usecases.fit_decode import imread_rgb
from rti_rig.app.usecases.fit_full_scale import acquisition_full_scale, stored_8_bit
from rti_rig.app.usecases.fit_inputs import (
    INPUTS_KEY,
    as_read,
    inputs_record,
)
from rti_rig.app.usecases.fit_maps import MapFile
from rti_rig.app.usecases.fit_memory import release_free_memory
from rti_rig.app.usecases.fit_outlook import auto_way_out, fit_outlook
from rti_rig.app.usecases.fit_rti_order import hsh_order
from rti_rig.app.usecases.fit_signal import no_signal_warning
from rti_rig.app.usecases.session_integrity import with_lost_files
from rti_rig.core import opencv_files
from rti_rig.core.acquisition_images import check_image_files, mixed_depth_words
from rti_rig.core.errors import ConfigError, LpFormatError, RtiRigError
from rti_rig.core.fit_minimums import FIT_MINIMUMS, PHOTOMETRIC_STEREO, AutoFit, auto_models
from rti_rig.core.image_files import (
    MOSAIC_TIFF_LABEL,
    header_layout,
    image_truncation,
    png_alpha_note,
)
from rti_rig.core.json_values import strict_dumps
from rti_rig.core.lp_format import (
    TITLE_HINT,
    LpEntry,
    acquisition_lp_files,
    case_hint,
    directions_of,
    format_lp,
    image_file_name,
    image_paths,
    lp_files_in,
    lp_name_from,
    parse_lp,
    read_lp,
)
from rti_rig.core.out_folders import (
    ensure_writable_folder,
    fit_beside,
    free_folder_beside,
    free_name,
    refuse_a_file_in_the_way,
)
from rti_rig.core.raw_rows import DecodedStore, RawRows
from rti_rig.core.shell_words import shell_word, shown_path
from rti_rig.core.tiff_rows import TiffRows
from rti_rig.drivers.cameras.colour_convert import needs_conversion, to_linear_srgb
from rti_rig.drivers.cameras.file_colour import (
    FileColour,
    exif_only_16_bit_notice,
    file_colour,
)
from rti_rig.reconstruct import exporters, signal_check
from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.full_scale import FullScale
from rti_rig.reconstruct.qa import ImageCheck, QAReport, assess
from rti_rig.reconstruct.registry import model_spec
from rti_rig.reconstruct.stack import ImageStack
from rti_rig.runtime.disowned import refuse_if_disowned
from rti_rig.runtime.session import (
    JOURNAL,
    LP_NAME,
    MANIFEST,
    UNRECORDED,
    checksum_session_files,
    journaled_checksums,
    list_unwritten_step,
    lost_image_advice,
    lp_again,
    read_manifest,
    refuse_if_in_use,
    remember_pixel_digest,
    renamed_note,
    renamed_since_capture,
    stopped_before_first_journal,
    unresumable,
    unwritten_step,
)

#: What ``--model`` accepts besides the registered model names.
AUTO = "auto"


class FitInputError(RtiRigError):
    """The session or .lp cannot be read for fitting."""


class FitOutputError(RtiRigError):
    """The fit's outputs could not be written (a full disk, a file-size limit, a read-only or
    failing disk): named, with the folder left as it was found and the command to run again."""


#: Errors that say the output could not be written, whichever file the OS names (a file
#: object's truncate names none).
_WRITE_ERRNOS = {errno.ENOSPC, errno.EFBIG, errno.EROFS, errno.EDQUOT}


def _output_write_failed(exc: OSError, out: Path) -> bool:
    """Whether ``exc`` is a failure to write the fit's outputs in ``out`` (not to read the
    session's images, which is said where they are read)."""
    if exc.errno in _WRITE_ERRNOS:
        return True
    name = exc.filename
    return bool(name) and Path(str(name)).resolve().is_relative_to(out.resolve())


def _output_error(exc: OSError, req: FitRequest, out: Path, created: bool) -> FitOutputError:
    """What a fit that could not write its outputs says: what failed, that nothing was kept
    and the session is unchanged, and the command to run again. Why: a full disk (or a
    file-size limit) met while the fit's files were written reached the user as a Python
    traceback ending in ``OSError: [Errno 27] File too large``."""
    code = errno.errorcode.get(exc.errno or 0, "")
    reason = f"{exc.strerror or exc}{f' ({code})' if code else ''}"
    where = f" ({shown_path(os.fsdecode(exc.filename))})" if exc.filename else ""
    left = "removed" if created else "emptied again"
    remedy = {
        errno.EFBIG: "raise the file-size limit (ulimit -f)",
        errno.EROFS: "choose an --out on a disk you can write to",
        # a folder gone under the fit is no full disk: two batches given one --out had each
        # been told to free space when the other removed its partial folder
        errno.ENOENT: (
            "its folder was removed while the fit wrote into it (by another run given the "
            "same --out, or a clean-up); let other runs end"
        ),
    }.get(exc.errno or 0, "free space on that disk, or choose an --out on another")
    if out.name.startswith(".") and out.name.endswith(".partial"):
        # a batch's hidden attempt folder is no --out to give: the batch is run again
        again = f"run the batch again with --out {shell_word(str(out.parent))}"
    else:
        again = f"run again: rti-rig fit {shell_word(str(req.source))} --out {shell_word(str(out))}"
    return FitOutputError(
        f"{shown_path(req.source)}: the fit could not write its outputs in "
        f"{shown_path(out)}{where}: {reason}; nothing of it was kept ({shown_path(out)} {left}) "
        f"and the session is unchanged: {remedy}, then {again}"
    )


@dataclass(frozen=True)
class FitRequest:
    source: Path
    out_dir: Path
    model: str = AUTO
    write_ptm: bool = True
    write_hsh: bool = True
    write_normals: bool = True
    hsh_order: int | None = None  # --hsh-order; None: fit_rti_order.hsh_order chooses
    qa: bool = True
    #: what fit.ptm and fit.rti hold: "srgb" (the photographs' encoded values, as RTIBuilder
    #: writes them and viewers show them) or "linear" (the fitted linear light: darker in a
    #: viewer, which applies no transfer curve). Normals are fitted to the linear light either way.
    export_encoding: str = "srgb"
    #: --white-level: the code the 16-bit images saturate at (None: 65535, or read from an
    #: imported acquisition's images, :mod:`rti_rig.app.usecases.fit_full_scale`)
    white_level: int | None = None


@dataclass
class FitResult:
    out_dir: Path
    model: str
    reason: str
    files: list[Path] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    qa: QAReport | None = None
    seconds: float = 0.0
    #: What the tolerant .lp reader accepted but the user should know (a light clamped to the
    #: horizon, a count line that disagrees): ``FILE, line N: ...``.
    notes: list[str] = field(default_factory=list)
    #: where the normal maps came from (``ps-robust``, ``ps``, ``lambert``, ``ptm``; ``""``
    #: when none were fitted)
    normals_from: str = ""
    #: fit.rti's HSH order and why (``""`` when no fit.rti was written)
    rti: str = ""
    #: the relighting models fitted (``ptm``, ``hsh1``…``hsh3``), written or kept for normals
    fitted: tuple[str, ...] = ()


def _srgb_to_linear16(img: np.ndarray) -> np.ndarray:
    x = np.arange(256) / 255.0
    lin = np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
    lut = np.round(lin * 65535).astype(np.uint16)
    return lut[img]


def read_image(path: Path) -> Any:
    """One image of an acquisition, row-readable as uint16: a :class:`TiffRows` (rows read on
    demand) for 16-bit TIFF, else decoded once into a temporary file (:class:`RawRows`; 8-bit
    taken as sRGB and linearised on read). The lazy Dask stack reads its chunks through this,
    in the process that computes them."""
    if not path.is_file():
        raise FitInputError(
            f"image {shown_path(path)} listed in the .lp is missing{case_hint([path])}"
        )
    if path.suffix.lower() in (".tif", ".tiff"):
        rows = TiffRows(path)  # read a band at a time, never whole
        _check_tiff_type(path, rows)
        colour = _colour_to_convert(path, rows.shape, rows.dtype)
        if colour is not None:
            return _converted_rows(rows, colour, str(path))[0]
        if rows.dtype == np.uint16:
            return rows  # type: ignore[return-value]
    img = _decode(path)
    colour = _colour_to_convert(path, img.shape, img.dtype)
    if colour is not None:
        return _converted_rows(img, colour, str(path))[0]
    return _decoded_rows(img, str(path))


#: rows of a frame converted to linear sRGB at a time (colour_convert's own band): the
#: float working set stays a band's, never a 24 MP frame's (about 1 GB in one piece)
_COLOUR_ROWS = 256


@dataclass(frozen=True)
class SaidColour:
    """What a colour image's file said of its colours and what the fit did: ``record`` is
    the conversion's (fit.json's ``image_colour``; None where the file was read as before)
    and ``clipped`` its out-of-gamut pixels, the number itself (:func:`colour_notes` had
    parsed it back out of the record's words)."""

    colour: FileColour
    record: dict[str, str] | None = None
    clipped: int = 0


def _colour_of(path: Path, shape: tuple[int, ...]) -> FileColour | None:
    """What ``path`` says of its colours, read once; None for a grey file (no primaries)."""
    return file_colour(path) if len(shape) == 3 else None


def _converts(colour: FileColour | None, shape: tuple[int, ...], dtype: Any) -> bool:
    """Whether pixels of ``colour`` are converted to linear sRGB (a known space other than
    sRGB, or 16-bit sRGB-encoded: :func:`needs_conversion`, the rule of the watched folder
    and the replay); not where they are read as before (8-bit sRGB or untagged through the
    sRGB table, 16-bit linear as they are, an unknown space as it is, said by
    :func:`colour_notes`)."""
    return colour is not None and shape[2] == 3 and needs_conversion(colour, np.dtype(dtype))


def _colour_to_convert(path: Path, shape: tuple[int, ...], dtype: Any) -> FileColour | None:
    """What ``path`` says of its colours where its pixels are converted (:func:`_converts`),
    else None."""
    colour = _colour_of(path, shape)
    return colour if _converts(colour, shape, dtype) else None


def _convert_into(
    source: Any, colour: FileColour, fd: int, offset: int
) -> tuple[dict[str, str], int]:
    """``source`` (rows of an H×W×3 image as its file stores them) converted to linear sRGB
    a band at a time and written, uint16, at ``offset`` of ``fd``; the conversion's record
    (:func:`to_linear_srgb`'s, counted over the whole frame) and its clipped pixels."""
    height, width = source.shape[0], source.shape[1]
    row_bytes = width * 3 * 2
    clipped, record = 0, {}
    for row in range(0, height, _COLOUR_ROWS):
        band = to_linear_srgb(np.asarray(source[row : row + _COLOUR_ROWS]), colour)
        data = memoryview(band.pixels.reshape(-1).view(np.uint8))
        if os.pwrite(fd, data, offset + row * row_bytes) != len(data):
            raise OSError(errno.ENOSPC, "short write of converted rows to a temporary file")
        clipped += band.clipped
        record = band.record
    record = {
        **colour.as_dict(),
        **record,
        "out_of_gamut_clipped": f"{clipped} of {height * width} pixels",
    }
    return record, clipped


def _converted_rows(source: Any, colour: FileColour, name: str) -> tuple[RawRows, SaidColour]:
    """``source`` converted to linear sRGB into a temporary file of its own, read back by
    rows (:func:`_decoded_rows`'s way), and what was done."""
    store = DecodedStore()
    record, clipped = _convert_into(source, colour, store.fileno(), 0)
    shape = (source.shape[0], source.shape[1], 3)
    rows = RawRows(store, 0, shape, np.dtype(np.uint16), None, name=name)
    return rows, SaidColour(colour, record, clipped)


def _check_tiff_type(path: Path, rows: TiffRows) -> None:
    """16-bit and 8-bit TIFFs are read as `plan` reads them (in the space they say,
    :func:`_colour_to_convert`; else 16-bit as linear, 8-bit as sRGB); anything else is
    refused with what to give instead, and so is a CFA mosaic (a session shot with
    ``decode.mode = "mosaic"``): one colour per photosite is no picture, and a fit of it is a
    checkerboard at the wrong white level (the black-subtracted sensor range, not 65535) that
    no viewer or check would question."""
    if rows.dtype not in (np.uint16, np.uint8):
        raise FitInputError(
            f"{shown_path(path)}: a {rows.dtype} TIFF; give 16-bit linear or 8-bit sRGB TIFFs (or "
            "JPEG/PNG)"
        )
    if rows.description.startswith(MOSAIC_TIFF_LABEL):
        raise FitInputError(
            f"{shown_path(path)} is a CFA mosaic (the session was shot with decode.mode = "
            '"mosaic"): one '
            "colour per pixel, not a picture, so it cannot be fitted; decode the camera's RAW "
            "files kept in the session's raw/ folder to linear RGB (demosaiced) TIFFs with "
            "your RAW converter, list them in an .lp and fit that, and set decode.mode = "
            '"demosaic" or "half" in the rig config for the next session'
        )


def _decoded_rows(img: np.ndarray, name: str) -> RawRows:
    """A decoded image moved to an unlinked temporary file and read back by rows (as the plain
    fit does, :func:`_open_frames`): a process that keeps an acquisition open (a Dask worker)
    then holds file handles, not every image decoded (72 × 24 MP would be ~10 GB)."""
    store = DecodedStore()
    os.pwrite(store.fileno(), memoryview(img.reshape(-1).view(np.uint8)), 0)
    lut = _SRGB_TO_LINEAR16 if img.dtype == np.uint8 else None
    return RawRows(store, 0, img.shape, img.dtype, lut, name=name)


def _decode(path: Path, into: np.ndarray | None = None) -> np.ndarray:
    """A compressed image decoded whole: uint16 linear TIFF, or 8-/16-bit JPEG/PNG (RGB);
    JPEG/PNG into ``into`` when it fits (:func:`rti_rig.app.usecases.fit_decode.imread_rgb`)."""
    if path.suffix.lower() in (".tif", ".tiff"):
        img = np.asarray(TiffRows(path)[:])
    else:
        why = image_truncation(path) if path.is_file() else None
        if why is not None:  # OpenCV would decode a JPEG anyway, the missing part grey
            # (a PNG cut short had been told only "cannot read image", after libpng's own line)
            kind = "PNG" if path.suffix.lower() == ".png" else "JPEG"
            raise FitInputError(
                f"image {shown_path(path)} is a damaged {kind}: {why}; copy it again from the "
                "camera or card"
            )
        decoded = imread_rgb(path, into)
        if decoded is None:
            raise FitInputError(
                f"cannot read image {shown_path(path)} (not a JPEG or PNG OpenCV decodes); save it "
                "again as JPEG, PNG or TIFF, or leave it out of the .lp"
            )
        img = decoded
    if img.dtype not in (np.uint8, np.uint16):
        raise FitInputError(f"{shown_path(path)}: expected 8- or 16-bit images, got {img.dtype}")
    return np.ascontiguousarray(img)


#: 8-bit sRGB code value -> linear 16-bit (JPEG/PNG inputs are decoded from sRGB).
_SRGB_TO_LINEAR16 = _srgb_to_linear16(np.arange(256, dtype=np.uint8))


def _open_frames(
    paths: list[Path],
    label: str,
    said: dict[int, SaidColour] | None = None,
) -> list[Any]:
    """Row-readable frames (uint16 linear) of ``paths``, each decoded at most once.

    Uncompressed 16-bit TIFFs (what sessions write) are read in place a band of rows at a
    time (:class:`TiffRows`). Compressed ones (zlib TIFFs of older sessions, JPEG, PNG) are
    decoded once, in parallel, into an unlinked temporary file and read back as
    :class:`RawRows`: every later pass (pixel sample, fit, QA) reads rows, never decodes, and
    nothing holds the acquisition in memory. 8-bit images are kept 8-bit there and linearised
    on read. A colour image whose file says a space other than sRGB (or a 16-bit sRGB-encoded
    one) is converted to linear sRGB a band of rows at a time as it is stored
    (:func:`_convert_into`); ``said`` gets each colour image's :class:`SaidColour`, by index
    (its file's colour read once).
    """
    frames: list[Any] = [None] * len(paths)
    pending = []
    for i, path in enumerate(paths):
        if not path.is_file():
            raise FitInputError(
                f"image {shown_path(path)} listed in {label} is missing (an .lp's image names are "
                f"read relative to its own folder){case_hint([path])}"
            )
        if path.suffix.lower() in (".tif", ".tiff"):
            rows = TiffRows(path)
            _check_tiff_type(path, rows)
            colour = _colour_of(path, rows.shape)
            if colour is not None and _converts(colour, rows.shape, rows.dtype):
                # read a band at a time, converted, never whole
                frames[i], done = _converted_rows(rows, colour, str(path))
                if said is not None:
                    said[i] = done
                continue
            if said is not None and colour is not None:
                said[i] = SaidColour(colour)
            if rows.dtype == np.uint16 and rows.reads_in_place:
                frames[i] = rows
                continue
        pending.append(i)
    if not pending:
        return frames
    first = _decode(paths[pending[0]])
    shape, stored = first.shape, first.dtype
    # one store per pixel type: an acquisition may mix 8-bit images (kept 8-bit, linearised
    # on read) with compressed 16-bit ones (a PNG or zlib TIFF export beside JPEGs), fitted
    # with a note (:func:`_mixed_depth_note`) as an uncompressed 16-bit TIFF beside them is;
    # one store of the first image's type had refused them as "(395, 402, 3) uint16"
    stores: dict[np.dtype[Any], tuple[DecodedStore, list[int]]] = {}
    claim = threading.Lock()

    def place_bytes(dtype: np.dtype[Any], nbytes: int) -> tuple[DecodedStore, int]:
        """The store of ``dtype`` and the offset reserved there for ``nbytes``."""
        with claim:
            store, end = stores.setdefault(dtype, (DecodedStore(), [0]))
            offset = end[0]
            end[0] += nbytes
        return store, offset

    def place(img: np.ndarray) -> tuple[DecodedStore, int]:
        """The store of ``img``'s type and the offset reserved there for it."""
        return place_bytes(img.dtype, img.nbytes)

    buffers = threading.local()  # one decode buffer per thread, reused image after image

    def put(k: int, img: np.ndarray | None = None) -> None:
        i = pending[k]
        if img is None:
            buffer = getattr(buffers, "image", None)
            if buffer is None:
                buffer = buffers.image = np.empty(shape, stored)
            img = _decode(paths[i], buffer)
        if img.shape != shape:
            raise FitInputError(
                f"images of {label} differ: {paths[pending[0]].name} is {_layout_words(shape)} "
                f"but {paths[i].name} is {_layout_words(img.shape)}; an acquisition has one "
                "image size and kind (replace those images, or list only the others)"
            )
        colour = _colour_of(paths[i], img.shape)
        if colour is not None and _converts(colour, img.shape, img.dtype):
            # converted a band at a time into the 16-bit store: linear sRGB, no table on read
            store, offset = place_bytes(np.dtype(np.uint16), img.shape[0] * img.shape[1] * 6)
            record, clipped = _convert_into(img, colour, store.fileno(), offset)
            frames[i] = RawRows(store, offset, img.shape, np.dtype(np.uint16), name=str(paths[i]))
            if said is not None:
                said[i] = SaidColour(colour, record, clipped)
            return
        if said is not None and colour is not None:
            said[i] = SaidColour(colour)
        store, offset = place(img)
        os.pwrite(store.fileno(), memoryview(img.reshape(-1).view(np.uint8)), offset)
        lut = _SRGB_TO_LINEAR16 if img.dtype == np.uint8 else None
        frames[i] = RawRows(store, offset, img.shape, img.dtype, lut, name=str(paths[i]))

    put(0, first)
    del first
    # the images are decoded in parallel already: OpenCV's own worker threads would only add
    # per-thread buffers (measured: 7 MB more at the peak, 21 MB kept after, at 2.5 MP)
    cv_threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        with ThreadPoolExecutor(max_workers=os.cpu_count() or 2, thread_name_prefix="decode") as ex:
            list(ex.map(put, range(1, len(pending))))
    finally:
        cv2.setNumThreads(cv_threads)
    return frames


def _resume_words(source: Path) -> str:
    """How to continue ``source`` (a session folder or an ``.lp`` in one) where it is an
    rti-rig session that did not finish (its manifest records no completed end); "" otherwise.

    Why: a session stopped after 2 of 12 images was told by ``fit`` "shoot more lights", and
    not that ``run --resume`` shoots the rest of the lights it planned (or, where no resume
    can continue it, what to do instead: :func:`unresumable`)."""
    folder = source if source.is_dir() else source.parent
    try:
        manifest = read_manifest(folder)
    except RtiRigError:
        return ""
    runner = manifest.get("runner") or {}
    if not isinstance(runner, dict) or runner.get("finish_reason") == "completed":
        return ""
    instead = unresumable(folder)
    if instead is not None:
        return f"the session is not finished: {instead}"
    return (
        "the session is not finished: continue it with rti-rig run --resume "
        f"{shell_word(str(folder))}"
    )


def _layout_words(shape: tuple[int, ...]) -> str:
    """An image's size and kind as a user reads them (``402x395 colour``), not a numpy shape."""
    return f"{shape[1]}x{shape[0]} {'colour' if len(shape) == 3 else 'greyscale'}"


def acquisition_files(
    source: Path, notes: list[str] | None = None
) -> tuple[Path, np.ndarray, list[Path], list[str]]:
    """The ``.lp`` of a session folder or ``.lp`` source, its lights (N, 3), the image file of
    each light (``linear/<stem>.tif`` when there, else the file the ``.lp`` names) and names."""
    refuse_if_in_use(source if source.is_dir() else source.parent, "fit it")
    if source.is_dir():
        lps = lp_files_in(source)
        if not lps:
            if (source / JOURNAL).is_file():  # a session that lost its lights.lp
                raise FitInputError(
                    f"{shown_path(source)} is a session folder without its {LP_NAME}; rebuild it "
                    f"from the session's journal with: rti-rig export-lp {shell_word(str(source))} "
                    f"--out {shell_word(str(source / LP_NAME))}"
                )
            first = stopped_before_first_journal(source)
            if first is not None:
                # killed before its first record; or after it, before its first journal line
                # (its image committed: "nothing recorded" had been said of it)
                instead = unresumable(source)  # a camera-triggered dome's resume is refused
                what = (
                    "stopped before its first image was recorded: there is nothing to fit yet"
                    if first == UNRECORDED
                    else f"stopped before its first journal line: {first} is kept (its record "
                    f"file proves it), but no {LP_NAME} lists it yet, and one image is too few "
                    "to fit"
                )
                raise FitInputError(
                    f"{shown_path(source)} is a session that {what}; "
                    + (
                        instead
                        if instead is not None
                        else f"continue it with rti-rig run --resume {shell_word(str(source))}"
                    )
                )
            if (source / MANIFEST).is_file():  # its journal and lights.lp both gone
                raise FitInputError(
                    f"{shown_path(source)} is a session folder without its {LP_NAME} and "
                    f"{JOURNAL}: its images cannot be paired with their lights or verified as "
                    "captured; restore both from a backup copy of the folder"
                )
            lps = acquisition_lp_files(source)  # an RTIBuilder project: its assembly-files/
            if not lps:
                # what to give said (a folder of images alone had been told only what it is not)
                raise FitInputError(
                    f"{shown_path(source)} holds no .lp file: not a session folder; give a "
                    "session folder, or the .lp that lists the images with their lights (a "
                    "count line, then 'name x y z' per image)"
                )
        if not (source / LP_NAME).is_file() and len(lps) > 1:
            # the first in name order had been fitted, said only of a session: a folder with
            # dirs.lp and a_subset.lp was fitted from the 4 lights of the subset, "good". The
            # way out names the file, the --out being the user's own (this reader has none):
            # "rti-rig fit X.lp --out DIR", pasted, made a folder named DIR
            shown = ", ".join(lp_name_from(source, p) for p in lps[:6]) + (
                " …" if len(lps) > 6 else ""
            )
            rebuild = (
                f"; or rebuild the session's own {LP_NAME} from its journal with: rti-rig "
                f"export-lp {shell_word(str(source))} --out "
                f"{shell_word(str(source / LP_NAME))}"
                if (source / JOURNAL).is_file()
                else ""
            )
            raise FitInputError(
                f"{shown_path(source)} holds {len(lps)} .lp files and no {LP_NAME} ({shown}): "
                "which one lists its lights cannot be told; fit the one you mean by giving it in "
                f"the folder's place, with the same --out (e.g. {shell_word(str(lps[0]))})"
                f"{rebuild}"
            )
        lp = source / LP_NAME if (source / LP_NAME).is_file() else lps[0]
        others = [p for p in lps if p.resolve() != lp.resolve()]
        if notes is not None and others and not (source / MANIFEST).is_file():
            # a folder that is no session, holding lights.lp and another .lp, was fitted from
            # lights.lp without a word, where bench tradeoff --from refuses the folder (QA,
            # 2026-12-05); a session's own lights.lp is never in doubt, an export beside it
            # (demo_linear.lp) is the guide's advice: no note there
            shown = ", ".join(lp_name_from(source, p) for p in others[:5]) + (
                " …" if len(others) > 5 else ""
            )
            notes.append(
                f"{shown_path(source)}: fitted from its {LP_NAME}, not the other .lp beside it "
                f"({shown}); to fit one of those, give it in the folder's place (e.g. "
                f"{shell_word(str(others[0]))})"
            )
        if notes is not None and lp.parent != source:
            notes.append(
                f"{shown_path(source)}: fitted from {shown_path(lp)} (RTIBuilder's layout)"
            )
        if notes is not None and lp.name != LP_NAME and (source / JOURNAL).is_file():
            # a session that lost its lights.lp had been fitted from another .lp in it (one
            # the user exported: a subset, say) without a word
            notes.append(
                f"{shown_path(source)} is a session folder without its {LP_NAME}: fitted from its "
                f"{lp.name}; rebuild {LP_NAME} from the session's journal with: rti-rig "
                f"export-lp {shell_word(str(source))} --out "
                f"{shell_word(str(source / LP_NAME))}"
            )
        if notes is not None and (source / JOURNAL).is_file() and not (source / MANIFEST).is_file():
            # a session (it has a journal) that lost its manifest had been fitted, and judged
            # "good", without a word: what it records (the rig, the plan, the exposure, the
            # lights' calibration) is gone, and run --resume refuses the folder
            notes.append(
                f"{shown_path(source)} is a session folder without its {MANIFEST}: fitted from its "
                f"{lp.name}, but its record of the rig, plan and exposure is missing and it "
                "cannot be resumed; restore the manifest from a copy of the session"
            )
    elif source.suffix.lower() == ".lp" and source.is_file():
        lp = source
    elif not source.exists():  # a typo had been told to "give a session folder or an .lp"
        raise FitInputError(
            f"{shown_path(source)} does not exist: give a session folder or an .lp file"
        )
    else:
        raise FitInputError(f"{shown_path(source)}: give a session folder or an .lp file")
    refuse_if_disowned(lp.parent)  # a session whose labels a late slip check disowned
    entries = _listed_entries(lp, notes)
    lights = directions_of(entries)
    session = (lp.parent / JOURNAL).is_file()  # it wrote a linear TIFF for every image
    paths, names, stand_ins = [], [], []
    damage: dict[Path, str | None] = {}  # a session's files checked, each read once
    for e, listed in zip(entries, image_paths(lp, entries), strict=True):
        stem = Path(image_file_name(e.name)).stem
        linear = lp.parent / "linear" / f"{stem}.tif"
        if session and linear.is_file():
            damage[linear] = _damage(linear)
        # a session's TIFF cut short or emptied (a copy interrupted) is read as a missing one
        # is, from its 8-bit file: the whole fit had been refused for it, and the verdict
        # names it as changed since capture all the same
        readable = linear.is_file() and not (damage.get(linear) and listed.is_file())
        paths.append(linear if readable else listed)
        names.append(stem)
        if not readable:
            stand_ins.append(e.name)
    if session:
        # gone, or cut short (a copy interrupted): the fit had stopped part-way at the first
        # short read, told to "leave it out of the .lp" of a session whose .lp it rewrites;
        # overwritten whole (its length kept): it had been refused by the decoder, told to
        # "leave it out of the .lp" of a session, not the session's own ways out. Named gone
        # first, then cut short, then overwritten
        damaged = [(p, why) for p in paths if (why := damage[p] if p in damage else _damage(p))]
        order = {"gone": 0, _OVERWRITTEN: 2}
        _refuse_lost_images(lp, sorted(damaged, key=lambda d: order.get(d[1], 1)))
    else:
        _refuse_unusable_images(lp, entries, paths)
    if notes is not None and stand_ins and (len(stand_ins) < len(entries) or session):
        # a session's linear/ lacks some TIFFs: their 8-bit files are read instead, said (the
        # fit had mixed lossy 8-bit data into a linear one without a word; and a session whose
        # linear/ was not copied with it was fitted from its JPEGs alone without one either)
        shown = ", ".join(stand_ins[:5]) + (" ..." if len(stand_ins) > 5 else "")
        beside = " beside linear 16-bit data" if len(stand_ins) < len(entries) else ""
        notes.append(
            f"{len(stand_ins)} of {len(entries)} image(s) have no readable linear/ TIFF and "
            f"were read from their 8-bit file instead ({shown}): lossy, sRGB-decoded "
            f"data{beside}; restore the TIFFs from a copy for a fully linear fit"
        )
    return lp, lights, paths, names


#: What a session's image whose header reads as no image's is said to be.
_OVERWRITTEN = "its header does not read as an image's (damaged, or another file over it)"


def _damage(path: Path) -> str | None:
    """Why a session's image file cannot be read as captured ("gone", cut short, or
    :data:`_OVERWRITTEN`), or None: what the refusal of its lost images names
    (:func:`image_truncation`, :func:`header_layout`), and what makes a linear TIFF be read
    from its JPEG instead."""
    if not path.is_file():
        return "gone"
    return image_truncation(path) or (_OVERWRITTEN if header_layout(path) is None else None)


def _refuse_unusable_images(lp: Path, entries: list[LpEntry], paths: list[Path]) -> None:
    """Refuse an ``.lp`` (not a session's) whose images to be read (``paths``: a
    ``linear/<stem>.tif`` in place of the listed file where there is one) are missing or not
    all of one size and kind (as their headers say), naming them all and what to do, before any
    pixel is decoded: in the words ``run`` and ``bench tradeoff --from`` use for the same `.lp`
    (:func:`check_image_files`).

    Why: the fit stopped at the first missing image of a relative name ("image acq/img_02.png
    ... is missing"), and said an image of another size part-way, as numpy shapes ("images of
    acq/a.lp differ: img_05.png is (40, 64, 3) uint8"), where run and bench named them all.
    From headers only: an image damaged or unreadable is named by the fit's own read of it."""
    listed = image_paths(lp, entries)
    # an image read from linear/ is named by that file, the listed name otherwise
    names = [
        e.name if p == q else p.relative_to(lp.parent).as_posix()
        for e, p, q in zip(entries, paths, listed, strict=True)
    ]
    try:
        check_image_files(
            lp,
            names,
            paths,
            use="fit",
            headers_only=True,
        )
    except ConfigError as exc:
        raise FitInputError(str(exc)) from None


def _refuse_lost_images(lp: Path, damaged: list[tuple[Path, str]]) -> None:
    """Refuse a session whose ``lp`` lists images that are gone (neither their linear TIFF nor
    the file listed on disk) or whose file to be read is cut short, naming them all with what
    to do.

    Why: such a fit stopped at the first one with "image S/image_004.jpg listed in
    S/lights.lp is missing (an .lp's image names are read relative to its own folder)", or
    part-way through at a short read, which named neither the others nor the session's own
    ways out (a copy, ``--reshoot-lost``, or an ``.lp`` of the images that remain from the
    journal)."""
    if not damaged:
        return
    root = lp.parent
    try:
        adaptive = bool(read_manifest(root).get("adaptive"))
    except RtiRigError:
        adaptive = False

    def one(path: Path, why: str) -> str:
        if why == "gone":
            return f"{path.stem}: neither its JPEG nor its linear TIFF on disk"
        return f"{path.relative_to(root).as_posix()}: {why}"

    shown = "; ".join(one(p, why) for p, why in damaged[:8]) + (" …" if len(damaged) > 8 else "")
    renamed = renamed_since_capture(root)
    moved = f" ({renamed_note(renamed)})" if renamed else ""
    there = {Path(name).stem for name in renamed}
    if all(why == "gone" and path.stem in there for path, why in damaged):
        raise FitInputError(  # all there, under other names: nothing to restore or reshoot
            f"{shown_path(root)}: {len(damaged)} image(s) its {lp.name} lists are not under their "
            f"session names: {renamed_note(renamed)}; then run this again"
        )
    folder = shell_word(str(root))
    rest = shell_word(str(free_name(root / "rest.lp")))  # export-lp refuses an existing one
    fit_out = shell_word(str(free_folder_beside(root, "fit")))  # ``--out DIR`` pasted made DIR
    raise FitInputError(
        f"{shown_path(root)}: {len(damaged)} image(s) its {lp.name} lists cannot be read as "
        f"captured ({shown}){moved}: {lost_image_advice(root, adaptive)}; or fit the images that "
        "remain, listed from the session's journal: rti-rig export-lp "
        f"{folder} --linear --out {rest}, then rti-rig fit {rest} --out {fit_out}"
    )


def listed_image_files(source: Path) -> list[str]:
    """The file name of each image of an acquisition, in its ``.lp``'s order (the order of
    the fit's lights): what relight lists in the images' folder."""
    lp, _, _, _ = acquisition_files(source)
    return [image_file_name(e.name) for e in _listed_entries(lp)]


def _listed_entries(lp: Path, notes: list[str] | None = None) -> list[LpEntry]:
    """The entries of ``lp``; of a session's ``lights.lp`` one image short (a run stopped
    between a step's record file and its journal line), with that image too, as
    :func:`complete_session_lp` writes it once the fit has passed its refusals.

    Why: the file had been rewritten before the fit's refusals, a disowned session's and one
    refused for a non-empty --out included, without a word. The completed listing is read from
    memory here, and the file left as it is until the fit's outputs are written. A folder that
    cannot be written is fitted from the file as it is (its verdict says the image is not
    fitted, which stays true)."""
    pending = unwritten_step(lp.parent) if lp.name == LP_NAME else None
    if pending is None or not _writable(lp):
        try:
            return read_lp(lp, upper_hemisphere=True, notes=notes)
        except LpFormatError as exc:
            raise _own_lp_unreadable(lp, exc) from None
    before, entry, _ = pending
    return parse_lp(format_lp([*before, entry]), str(lp), upper_hemisphere=True, notes=notes)


def _own_lp_unreadable(lp: Path, exc: LpFormatError) -> LpFormatError:
    """``exc``, of a session's own ``lights.lp`` (its folder holds a journal), with the mend
    of a listing rti-rig wrote: written again from the journal.

    Why: a finished session's lights.lp cut short was told "line 9: expected 'name x y z',
    found 1 field(s): 'image_0' (a title or a row of column headings? … delete the line …)",
    advice that deletes a light, and an emptied one "the file is empty" with no mend."""
    if lp.name != LP_NAME or not (lp.parent / JOURNAL).is_file():
        return exc
    return LpFormatError(
        exc.path,
        exc.line,
        exc.message.replace(TITLE_HINT, "")
        + f"; it is the session's listing of the lights that fired (cut short, emptied or "
        f"edited since?): {lp_again(lp)}",
    )


def _writable(lp: Path) -> bool:
    """Whether ``lp`` and its folder can be written (the atomic rewrite replaces the file)."""
    return os.access(lp, os.W_OK) and os.access(lp.parent, os.W_OK)


def complete_session_lp(source: Path) -> str | None:
    """Complete the ``lights.lp`` of session ``source`` (a folder or its ``lights.lp``) that a
    run stopped between a step's record file and its journal line left one image short; what
    was done, or None. Called by the fit only once every refusal has passed: never of a
    disowned session (:func:`list_unwritten_step` leaves those alone too)."""
    source = Path(source)
    if source.is_dir():
        root = source
    elif source.name == LP_NAME:
        root = source.parent
    else:
        return None
    return list_unwritten_step(root)


def acquisition_inputs(source: Path, files: dict[str, Path] | None = None) -> dict[str, Any] | None:
    """The record of what a fit of ``source`` reads (:func:`inputs_record`: its images by the
    checksums its session's journal holds, if it has one), or None when it cannot be read as an
    acquisition (the fit itself says why). ``files``, if given, is filled with each image's
    file by its name in the record (a batch hashes the one whose size or time changed)."""
    try:
        lp, lights, paths, names = acquisition_files(source)
    except (RtiRigError, OSError, ValueError):
        return None
    if files is not None:
        files.update((str(n), Path(p)) for n, p in zip(names, paths, strict=True))
    try:
        journaled = journaled_checksums(lp.parent)
    except (RtiRigError, OSError):  # a journal that cannot be read: its images by their files
        journaled = None
    try:
        return inputs_record(lights, paths, names, lp.parent, journaled)
    except (RtiRigError, OSError, ValueError):
        return None


def _shapes_differ(lp: Path, shapes: list[tuple[int, ...]], paths: list[Path]) -> str:
    """Which images are not of the acquisition's size, by name, against the size most of its
    images have. Why: "images of S/lights.lp differ in shape: [(400, 400, 3), (512, 512,
    3)]" named no file, so a user had to open every image to find the one replaced."""
    from collections import Counter

    common = Counter(shapes).most_common(1)[0][0]
    odd = [(p, s) for p, s in zip(paths, shapes, strict=True) if s != common]

    def size(shape: tuple[int, ...]) -> str:
        return f"{shape[1]}×{shape[0]}" + (f"×{shape[2]}" if len(shape) > 2 else "")

    shown = ", ".join(
        f"{p.relative_to(lp.parent) if p.is_relative_to(lp.parent) else p} ({size(s)})"
        for p, s in odd[:5]
    )
    more = f" and {len(odd) - 5} more" if len(odd) > 5 else ""
    return (
        f"images of {shown_path(lp)} differ in size: {len(shapes) - len(odd)} are "
        f"{size(common)} (width × height × channels), but {shown}{more} "
        f"{'is' if len(odd) == 1 else 'are'} not: replaced or edited since capture? Put the "
        "originals back from a copy, or leave those out of the .lp"
    )


def load_acquisition(
    source: Path,
    notes: list[str] | None = None,
    colours: dict[str, dict[str, str]] | None = None,
) -> tuple[list[Any], np.ndarray, list[str], str]:
    """Frames (row-readable, uint16 linear), lights (N, 3), image names, and a description
    of what was read; the .lp reader's notes, and what the fit did of the files' colour
    spaces, are appended to ``notes``; ``colours`` gets each colour image's record by name
    (fit.json's ``image_colour``)."""
    lp, lights, paths, names = acquisition_files(source, notes)
    said: dict[int, SaidColour] = {}
    frames = _open_frames(paths, str(lp), said)
    if colours is not None:
        for i, done in sorted(said.items()):
            colours[names[i]] = done.record or {
                **done.colour.as_dict(),
                "read_as": _read_as(frames[i]),
            }
    if notes is not None:
        sixteen = {i for i in said if not stored_8_bit(frames[i])}
        notes.extend(colour_notes(lp, said, len(paths), sixteen))
    shapes = {f.shape for f in frames}
    if len(shapes) != 1:
        raise FitInputError(_shapes_differ(lp, [f.shape for f in frames], paths))
    if notes is not None and not any(p.parent.name == "linear" for p in paths):
        # (a session's linear/ with stand-ins is said by acquisition_files); a converted
        # file's reading is its own file's, said by colour_notes, neither of the two guesses
        guessed = [i for i in range(len(paths)) if (i not in said or said[i].record is None)]
        notes.extend(
            _mixed_depth_note(lp, [frames[i] for i in guessed], [paths[i] for i in guessed])
        )
    if notes is not None:
        # dropped by the reader: said once, by the files' names (``names`` are stems)
        notes.extend(png_alpha_note([p.name for p in paths], paths))
    # the description is fit.json's "read", a record beside its raw "source" (the argument as
    # given), never printed: not a shell word, but absolute, as the manifest records its paths
    # (resolved, the name's bytes kept): 'fit ../s' had recorded "from ../s/lights.lp", which
    # named nothing once read from anywhere but the folder the fit was run in
    return frames, lights, names, f"{len(frames)} images from {Path(lp).resolve()}"


def _read_as(frame: Any) -> str:
    """How the fit read a colour image it did not convert (fit.json's ``image_colour``)."""
    if stored_8_bit(frame):
        return "8-bit, decoded through the sRGB curve"
    return "16-bit, taken as linear (no curve undone, primaries kept)"


def colour_notes(
    lp: Path,
    said: dict[int, SaidColour],
    n: int,
    sixteen: Collection[int] = (),
) -> list[str]:
    """What the fit says of the files' colour spaces: the images converted to linear sRGB
    (by space), those whose colours sRGB cannot show (clipped, counted), those of a space
    rti-rig does not know (fitted as they are), and the 16-bit ones (indices ``sixteen``)
    said sRGB by their Exif alone (taken as linear); nothing of other sRGB or untagged files,
    read as the fit always read them. Why: an acquisition's 8-bit files were taken as sRGB and
    16-bit ones as linear whatever the file said, an Adobe RGB JPEG or a ProPhoto TIFF
    (Lightroom's default export) fitted with another space's curve and primaries, silently,
    where a session of the same files converts them and says so."""
    by_name: dict[str, tuple[FileColour, list[int], int]] = {}
    exif_linear = [
        i
        for i, d in said.items()
        if d.record is None and d.colour.exif_linear and d.colour.space == "srgb" and i in sixteen
    ]
    for i, done in sorted(said.items()):
        colour, record = done.colour, done.record
        if record is None and colour.space != "other":
            continue
        key = (
            f"{colour.space} {colour.name} {colour.said_by} {colour.linear_curve} {record is None}"
        )
        c, images, clipped = by_name.get(key, (colour, [], 0))
        by_name[key] = (c, [*images, i], clipped + (done.clipped > 0))
    notes = []
    for key, (colour, images, clipped) in by_name.items():
        count = f"{len(images)} of {n} image(s) of {shown_path(lp)}"
        if key.endswith("True"):
            notes.append(
                f"{count} are {colour.name} (said by {colour.said_by}), a space rti-rig does "
                "not convert: fitted as they are (8-bit through the sRGB curve, 16-bit as "
                "linear), their colours that space's; for a fit in sRGB, export them as sRGB"
            )
            continue
        done = (
            "the fit took their values as linear, as its curve (gamma 1.0) says, not through "
            "the sRGB curve"
            if colour.linear_curve
            else "the fit undid its curve"
        )
        # an sRGB file's primaries are sRGB's already: only its curve was read differently,
        # and a note saying its primaries were converted claims a step never taken
        primaries = (
            ", its primaries kept (sRGB's already),"
            if colour.space == "srgb"
            else " and converted its primaries to linear sRGB's"
        )
        notes.append(
            f"{count} are {colour.name} (said by {colour.said_by}): {done}{primaries} before "
            "fitting (the files are untouched); fit.json's image_colour says what was done "
            "to each"
        )
        if clipped:
            notes.append(
                f"some colours of {clipped} of those {colour.name} image(s) lie outside sRGB's "
                "gamut and were clipped to it for the fit (fit.json's image_colour counts "
                "the pixels of each)"
            )
    if exif_linear:
        notes.append(
            exif_only_16_bit_notice(f"{len(exif_linear)} of {n} image(s) of {shown_path(lp)}")
        )
    return notes


def _mixed_depth_note(lp: Path, frames: list[Any], paths: list[Path]) -> list[str]:
    """A note when an acquisition mixes 8-bit images (decoded as sRGB) with 16-bit ones (taken
    as linear, as sessions write them): one 16-bit export that is gamma-encoded, not linear,
    beside JPEGs would be fitted several times too bright in its mid-tones, silently. Both
    readings are the documented ones, so the files are fitted; the user is told to check, in
    the words replay and check use (:func:`mixed_depth_words`)."""
    eight = [p.name for f, p in zip(frames, paths, strict=True) if stored_8_bit(f)]
    sixteen = [p.name for f, p in zip(frames, paths, strict=True) if not stored_8_bit(f)]
    note = mixed_depth_words(lp, eight, sixteen, "fitted")
    return [note] if note else []


#: How the bands of a fit are computed: given the stack, the plan and the row tiles, yield each
#: tile with its :class:`BandFit` (any order). :func:`local_bands` by default; the Dask runner
#: of :mod:`rti_rig.app.usecases.fit_dask` computes them on a scheduler.
BandRunner = Callable[[ImageStack, BandPlan, list[slice]], Iterator[tuple[slice, BandFit]]]


def prepare_out_dir(out: Path) -> None:
    """Create ``out`` (new or empty), or refuse clearly: never write over earlier outputs."""
    if out.exists() and not out.is_dir():
        raise FitInputError(
            f"--out {shown_path(out)} exists and is not a folder: choose another --out"
        )
    try:
        if out.exists() and any(out.iterdir()):
            # a folder not there yet, named, as run's refusal names one: "choose another
            # --out" had left the user to find a free name
            fresh = (
                f"--out {shell_word(str(free_name(out, folder=True)))}, which does not exist yet"
            )
            unfinished = _unfinished_fit(out)
            if unfinished:
                raise FitInputError(
                    f"{shown_path(out)} holds the outputs of a fit that did not finish "
                    f"({unfinished}; its fit.json, written last, is missing): the fit was killed, "
                    "or the machine stopped (out of memory?); delete that folder, or those files, "
                    f"and run this again, or choose another --out (such as {fresh})"
                )
            raise FitInputError(
                f"{shown_path(out)} is not empty: fit writes into a new or empty folder; "
                f"choose another --out (such as {fresh})"
            )
    except OSError as exc:
        raise FitInputError(
            f"--out {shown_path(out)}: cannot read it ({exc.strerror or exc})"
        ) from None
    try:
        ensure_writable_folder(out)
    except RtiRigError as exc:
        raise FitInputError(str(exc)) from None


#: Files a fit writes before its fit.json (written last): one of them without a fit.json is
#: what a fit killed outright (SIGKILL, an out-of-memory kill, a power cut) left.
_FIT_OUTPUTS = ("normals.npy", "albedo.npy", "fit.ptm", "fit.rti", "lights.dome", "qa.json")


def _unfinished_fit(out: Path) -> str:
    """The files of a fit that did not finish in folder ``out`` (``""`` when none).

    Why: a fit killed outright cannot clean up after itself, and its ``--out`` (gigabytes of
    ``*.part`` and ``.npy`` files at 24 MP) was then refused as merely "not empty", which did
    not say whose files they were or whether they could go."""
    if (out / "fit.json").exists():
        return ""
    found = sorted(
        p.name for p in out.iterdir() if p.name.endswith(".part") or p.name in _FIT_OUTPUTS
    )
    return ", ".join(found[:6]) + (" …" if len(found) > 6 else "")


def _discard_outputs(out: Path, created: bool) -> None:
    """Remove what a failed fit wrote into ``out`` (checked new or empty before it began), and
    ``out`` itself if this run created it."""
    import shutil

    if created:
        shutil.rmtree(out, ignore_errors=True)
        return
    for path in list(out.iterdir()) if out.is_dir() else []:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)


def refuse_out_inside_a_session(out: Path) -> None:
    """Refuse an ``--out`` inside a session folder (one holding rti-rig's manifest or
    journal), in the words ``run`` refuses one.

    Why: ``fit SESSION --out SESSION/fitout`` wrote the fit among the session's images and
    exited 0, where ``run --out SESSION/sub`` refuses: a copy of the session then carries the
    fit, and a fit of it or a ``--resume`` meets files that are not its capture's."""
    from rti_rig.runtime.session import enclosing_session

    outer = enclosing_session(out)
    if outer is not None:
        raise RtiRigError(
            f"--out {shown_path(out)} is inside {shown_path(outer)}, a session folder: give an "
            "--out outside it, so that each session stays a folder of its own"
        )


def run_fit(req: FitRequest, bands: BandRunner | None = None) -> FitResult:
    """Fit, write every output into ``req.out_dir``, and judge the acquisition.

    ``bands`` computes the per-band fits (default: in this process, :func:`local_bands`);
    everything else — model choice, quantisation ranges, writing, QA — is the same code. A fit
    that fails (or is interrupted) leaves ``req.out_dir`` as it found it: a refused fit had
    left model_choice.md behind, and the corrected command then found --out not empty.
    """
    t0 = time.perf_counter()
    # a file given for --out, or a folder the user may not look into (Path.exists raises
    # PermissionError on Python 3.11: a traceback), refused by name before any image is read
    refuse_a_file_in_the_way(req.out_dir)
    refuse_out_inside_a_session(req.out_dir)
    notes: list[str] = []
    inputs = acquisition_inputs(req.source)  # before reading: a later change is a change
    colours: dict[str, dict[str, str]] = {}
    frames, lights, names, what = load_acquisition(req.source, notes, colours)
    # an image converted from its file's colour space has no "read_as" (its record instead)
    converted = [n for n, c in colours.items() if "read_as" not in c]
    full = acquisition_full_scale(frames, names, Path(req.source), req.white_level, converted)
    if full is not None:
        notes.append(full.words(len(frames), shown_path(req.source)))
    said_at = len(notes)  # the repeated lights' note goes here, once what was fitted is known
    release_free_memory()  # the decode buffers
    out = req.out_dir
    created = not out.exists()
    prepare_out_dir(out)
    # the QA checks every captured file against its journaled checksum: hashed while the fit
    # works (hashing releases the GIL), not after it; a TIFF the fit reads in place gets its
    # pixel checksum from the fit's own pass through its rows, not from a second read
    pool, stop = ThreadPoolExecutor(max_workers=1), threading.Event()
    in_place = [f.path for f in frames if isinstance(f, TiffRows)]
    checksums = (
        pool.submit(checksum_session_files, Path(req.source), stop.is_set, in_place)
        if req.qa
        else None
    )
    try:
        result = _fit_into(
            req,
            out,
            frames,
            lights,
            names,
            what,
            notes,
            bands,
            checksums,
            inputs=inputs,
            colours=colours,
            full=full,
        )
    except BaseException as exc:
        stop.set()  # a failed or interrupted fit does not wait for the checksums
        _discard_outputs(out, created)  # ``out`` was new or empty: what is in it is this run's
        if isinstance(exc, OSError) and _output_write_failed(exc, out):
            raise _output_error(exc, req, out, created) from None
        raise
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
    # the model asked for is named even where only another source's normals were written
    # (``--model ptm --no-ptm``): it is the model the user chose
    repeated = repeated_lights_note(lights, names, fitted=(*result.fitted, result.model))
    if repeated is not None:
        result.notes.insert(said_at, repeated)
    result.seconds = time.perf_counter() - t0
    return result


def repeated_lights_note(
    lights: np.ndarray, names: Sequence[str], *, fitted: Sequence[str] = ("ptm", "hsh2", "hsh3")
) -> str | None:
    """What a fit says of lights that repeat a direction, whatever its model, or None.

    Why: a plan or a dome's calibration that repeats a light is refused, saying so, but a fit
    of 7 images of which 3 share one direction said nothing of it with ``--model ptm``: only
    "these lights cannot separate its 6 terms", leaving the user to find that 7 images gave
    5 directions. The models the distinct lights are too few for are named (the coefficient
    counts of ``core.fit_minimums``), only those this fit made (``fitted``: written, or kept
    for the normals): with ``--no-ptm`` a PTM had been called "fitted ridge-regularised and
    not to be trusted" of a fit that made none, and hsh2 of a fit whose fit.rti was hsh1."""
    from rti_rig.core.fit_minimums import N_COEFFICIENTS
    from rti_rig.core.rig_geometry import COINCIDENT_LED_DEG, repeated_directions

    groups = repeated_directions(lights)
    if not groups:
        return None
    n = len(lights)
    distinct = n - sum(len(g) - 1 for g in groups)
    shown = [", ".join(str(names[i]) for i in g[:-1]) + f" and {names[g[-1]]}" for g in groups[:4]]
    more = f" and {len(groups) - 4} more groups" if len(groups) > 4 else ""
    share = "share one direction" if len(groups) == 1 else "each share a direction"
    named = [m for m in ("ptm", "hsh1", "hsh2", "hsh3") if m in fitted]
    short = [m for m in named if distinct < N_COEFFICIENTS[m] <= n]
    tail = (
        "; too few distinct for "
        + ", ".join(f"--model {m} ({N_COEFFICIENTS[m]} terms)" for m in short)
        + ", fitted ridge-regularised and not to be trusted: add lights at other directions"
        if short
        else ""
    )
    return (
        f"lights repeated: {'; '.join(shown)}{more} {share} (within "
        f"{COINCIDENT_LED_DEG:g}°): the {n} images give {distinct} distinct lights, and a "
        f"repeat adds no direction to the fit{tail}"
    )


def _fit_into(  # type: ignore[no-untyped-def]
    req: FitRequest,
    out: Path,
    frames,
    lights,
    names,
    what: str,
    notes: list[str],
    bands,
    checksums: Future[None] | None = None,
    *,
    inputs: dict[str, Any] | None = None,
    colours: dict[str, dict[str, str]] | None = None,
    full: FullScale | None = None,
) -> FitResult:
    """Every output of :func:`run_fit` written into the prepared ``out`` (``checksums``: the
    session's files being checksummed meanwhile, awaited before the QA; ``inputs``: the record
    of what was read, :func:`acquisition_inputs`, kept in ``fit.json`` for a batch's rerun;
    ``full``: the full scale the images are fitted and judged against, where not 65535)."""
    # uint16, scaled on the fly; saturation at the top code, or at the full scale read
    stack = (
        ImageStack(frames)
        if full is None
        else ImageStack(frames, scale=1.0 / full.level, saturation_level=1.0)
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = _fit_all(req, stack, lights, out, bands or local_bands, names=names)
    # every refusal has passed and the fit's outputs are written: only now is the session's
    # lights.lp completed (it had been rewritten before them, of refused sessions too)
    relisted = complete_session_lp(Path(req.source))
    if relisted is not None:
        notes.append(relisted)
    result.warnings = [str(w.message) for w in fit_warnings(caught)] + result.warnings
    result.notes = notes
    result.files.append(
        exporters.write_relight_dome(
            out / "lights.dome",
            lights,
            # absolute, as fit.json's "read" is: the source as given ('../assembly-files/
            # icon.lp') named nothing to a user opening the fit folder from anywhere else later
            label=str(Path(req.source).resolve()),
            image_names=listed_image_files(req.source),
        )
    )
    release_free_memory()  # the fit's bands and PNG buffers, before QA reads the images again
    if req.qa:
        if checksums is not None:
            with contextlib.suppress(Exception):  # the QA's own check says what went wrong
                checksums.result()
        try:
            no_qa = qa_without_normals(lights)
            if no_qa is not None:
                raise ReconstructionError(no_qa)
            with warnings.catch_warnings(record=True) as qa_caught:
                warnings.simplefilter("always")
                # every row of every frame: checksummed too
                qa = assess(
                    frames, lights, names, saturation=None if full is None else float(full.level)
                )
            _say_qa_trust_warnings(qa_caught, result.warnings)
            _remember_pixels(frames)
            result.qa = with_lost_files(qa, req.source)
        except ReconstructionError as exc:  # e.g. coplanar lights for PS, 1-px images
            result.warnings.append(f"QA not possible: {exc}")
        else:
            result.files += write_qa_report(out, result.qa, result)
    if inputs is not None and len(inputs["images"]) == len(frames):
        inputs = as_read(inputs, [_read_pixels(f) for f in frames])
    summary = {
        "source": str(req.source),
        "read": what,
        "model": result.model,
        "why": result.reason,
        # the normal maps' estimator (robust PS unless the model used is PS, Lambert or the
        # PTM: also when auto chose it)
        "normals_from": result.normals_from or None,
        "rti": result.rti or None,
        # what fit.ptm / fit.rti hold (a viewer cannot tell: neither format records it)
        "export_encoding": req.export_encoding,
        "warnings": result.warnings,
        "input_notes": result.notes,
        # what each colour image's file says of its space and what the fit did of it
        # (converted to linear sRGB, with its clipped pixels; or how it was read as it is)
        "image_colour": colours or None,
        # the code read as white where not the files' 65535 (--white-level, or read from an
        # imported acquisition's images: a clip, shifted or 10/12-bit data)
        "full_scale": full.as_dict() if full is not None else None,
        "files": [p.name for p in result.files],
        "verdict": result.qa.verdict if result.qa else None,
        INPUTS_KEY: inputs,
    }
    (out / "fit.json").write_text(json.dumps(summary, indent=1) + "\n", encoding="utf-8")
    result.files.append(out / "fit.json")
    return result


def _say_qa_trust_warnings(caught: list[warnings.WarningMessage], said: list[str]) -> None:
    """The QA's trust warnings (its photometric-stereo fit's) added to the fit's ``said``
    warnings, each once; any other warning is issued again to the caller's filters.

    Why: the QA runs after the fit's own warning capture, so its photometric-stereo warning
    reached the console's safety net and was printed as a "note:" (and left out of
    ``fit.json``), where the PTM and HSH trust warnings about the same result are warnings."""
    from rti_rig.reconstruct.errors import FitTrustWarning

    for w in fit_warnings(caught):
        if not issubclass(w.category, FitTrustWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        elif str(w.message) not in said:
            said.append(str(w.message))


#: The fewest lights whose 5-fold cross-validation leaves a PTM its 6 fitting lights in every
#: fold: below, a fit.ptm is written with a word on what it is worth.
PTM_MEASURED_FROM = 8
#: The highest HSH order relight reads from an ``.rti``: its ``convertRTI`` (src/cli/
#: convert_rti.cpp, through ``LRti``'s 9-entry HSH plane order in src/legacy_rti.cpp) and its
#: viewer's ``Rti::lightWeightsHsh`` (src/rti.cpp, 9 weights) know 4 or 9 terms, and its
#: converter back to ``.rti`` refuses any other plane count. RTIViewer reads 16. So do not
#: the web viewer's converter webGLRtiMaker (its ``Hsh`` keeps 9 scales, biases and planes:
#: jcupitt/webRTIViewer ``webGLRTIMaker-src/rti.h``; 16 overrun them) and JedMills'
#: RTIViewer (``src/ptmCreation/RTIParser.java`` keeps terms 0-8 and drops the rest).
RELIGHT_HSH_ORDER = 2

#: Pixel sample shared by model choice, quantisation ranges and the reference level: one
#: decode pass of the files for all three, and the no-signal check's, which the QA's "black
#: throughout" shares.
SAMPLE_PIXELS = signal_check.SAMPLE_PIXELS


def sample_size(stack: ImageStack) -> int:
    """Pixels of the fit's shared sample for this stack: ``SAMPLE_PIXELS``, fewer at many
    lights, so that the sample (held whole) stays within a fixed number of values
    (:func:`rti_rig.reconstruct.signal_check.sample_pixels`)."""
    return signal_check.sample_pixels(stack.n, stack.channels)


#: Working-set budget of one band of the stack in the streamed fit (float32 bytes): small, so
#: that the fit's temporaries (robust PS keeps ~15 arrays of the band's pixels) stay bounded.
#: Measured at 72 images × 2.5 MP (3 rows a band): 8 MB put the band phase of a normals fit at
#: ~104 MB, relight's 108 MB less noise; 6 MB ~95 MB. 4 MB (2 rows) cost uncompressed-TIFF
#: sessions ~40 % more CPU (the band reads of 72 files each, not the fit, set the pace).
#: The outputs do not depend on it (tests/app/test_fit_memory.py).
BAND_BUDGET_BYTES = 6 * 1024 * 1024


def _fit_all(
    req: FitRequest,
    stack: ImageStack,
    lights: np.ndarray,
    out: Path,
    bands: BandRunner,
    names: Sequence[str] = (),
) -> FitResult:
    """One streamed pass over the acquisition: every output is computed band by band.

    Each band of rows of all images is read once (from the TIFFs, a strip at a time) and fitted
    by photometric stereo (normals, albedo) and by the PTM and HSH written to ``.ptm`` and
    ``.rti``; nothing holds the stack as floats. The 8-bit quantisation ranges of the exported
    coefficients come from a fit of the same pixel sample model choice uses (widened by 50 %;
    values beyond are clipped, and counted in ``fit.json``). The bands themselves are fitted
    by :func:`rti_rig.app.usecases.fit_bands.fit_band`, run by ``bands``.
    """
    from rti_rig.core.image_files import srgb_encode
    from rti_rig.core.rti_bases import design_matrix
    from rti_rig.reconstruct.errors import FitTrustWarning
    from rti_rig.reconstruct.model_select import select_model
    from rti_rig.reconstruct.solve import solve_matrix
    from rti_rig.reconstruct.tiling import row_tiles, rows_for_budget

    files: list[Path] = []
    name = req.model
    n = stack.n
    choice = None
    if req.hsh_order and req.write_hsh and n < (req.hsh_order + 1) ** 2:  # asked: refused
        raise FitInputError(
            f"--hsh-order {req.hsh_order} has {(req.hsh_order + 1) ** 2} coefficients per pixel "
            f"and needs at least {(req.hsh_order + 1) ** 2} lights; {shown_path(req.source)} has "
            f"{n}: choose a lower order, or leave --hsh-order out"
        )
    if name == AUTO:
        candidates, undetermined = auto_candidates(lights)
        left_out = ""
        if undetermined and req.write_normals:
            # why, once: the warning that the normal maps are not written gives the lights'
            # layout and condition number (both lines had, word for word)
            left_out = (
                "; Lambert left out of the choice: these lights cannot determine a surface "
                "normal (the warning below says why), so only the PTM and HSH, "
                "ridge-regularised, are written, and no normal maps"
            )
        elif undetermined:  # --no-normals: no normals warning, so the reason is said here
            left_out = (
                f"; Lambert left out of the choice: {undetermined}, so only the PTM and HSH, "
                "ridge-regularised, are written"
            )
        try:
            choice = select_model(
                stack, lights, max_pixels=sample_size(stack), candidates=candidates
            )
        except ReconstructionError as exc:
            resume = _resume_words(Path(req.source))
            if n < FIT_MINIMUMS.normal:  # no normal either: the choice's refusal stands
                if not resume:
                    raise
                raise FitInputError(f"{exc}; {resume}") from None
            raise FitInputError(
                f"--model auto: {exc}. "
                + (f"{resume[0].upper()}{resume[1:]}. " if resume else "")
                + (
                    f"Nor can photometric stereo be fitted: {undetermined}; "
                    + auto_way_out(AutoFit(n, normals_determined=False))
                    if undetermined
                    else "Photometric stereo alone (normals and albedo, no relighting model) "
                    "may still be fitted: --model ps"
                )
            ) from None
        model_name = choice.model
        (out / "model_choice.md").write_text(choice.to_markdown() + "\n", encoding="utf-8")
        files.append(out / "model_choice.md")
        reason_line = (
            # "simplest": lambert, ps and a PTM are among the models, and have no "order"
            f"{choice.model}: the simplest model within {choice.tolerance:.0%} of the best "
            f"held-out error ({choice.best_model}), {choice.holdout}{left_out}"
        )
    else:
        spec = model_spec(name)
        model_name = spec.name
        if n < spec.n_coefficients:  # asked for by name: refused, never silently not fitted
            raise FitInputError(
                f"--model {name} has {spec.n_coefficients} coefficients per pixel and needs at "
                f"least {spec.n_coefficients} lights; {shown_path(req.source)} has {n}: choose a "
                "smaller model, or --model auto"
            )
        # named as typed: `--model robust-ps` had been echoed as its alias "ps-robust"
        reason_line = f"{name}: chosen by --model"
    normal_source = _normal_source(model_name)
    skipped: list[str] = []  # said, never silently left out
    write_normals = req.write_normals
    if write_normals and normal_source in ("ptm", "ps-robust") and model_name != "ps-robust":
        # the normals a relighting model brings along: robust PS is asked for by name
        normal_source, why = conditioned_normal_source(normal_source, lights)
        write_normals = bool(normal_source)
        if why:
            skipped.append(why)
    elif model_name in PHOTOMETRIC_STEREO:  # normals are the model: none, no fit
        _refuse_undetermined_normals(req, model_name, lights)
    reason_line += _model_not_written(req, model_name, write_normals and normal_source == "ptm")

    # linear models to export, their solve matrices (warnings issued once, here)
    order, rti_why = rti_order(stack, lights, req, model_name, choice)
    linear: dict[str, np.ndarray] = {}
    if req.write_ptm and n >= FIT_MINIMUMS.ptm:
        linear["ptm"] = design_matrix("ptm", lights)
        if n < PTM_MEASURED_FROM:  # written, but the user should know what it is worth
            skipped.append(
                f"fit.ptm is written from {n} lights: a PTM's {FIT_MINIMUMS.ptm} coefficients "
                "are fitted with almost nothing to spare and its error on other directions "
                "cannot be measured "
                f"below {PTM_MEASURED_FROM} lights (on a real acquisition at 6 lights it relit "
                "held-out lights 5-6.5 dB below an order-1 HSH: docs/reconstruction.md); prefer "
                "fit.rti"
            )
    elif req.write_ptm:
        skipped.append(
            f"fit.ptm not written: a PTM needs at least {FIT_MINIMUMS.ptm} lights, there are {n}"
        )
    if req.write_hsh and order is None:
        skipped.append(rti_why)
    elif req.write_hsh and n >= FIT_MINIMUMS.hsh(order):
        linear[f"hsh{order}"] = design_matrix(f"hsh{order}", lights)
        if order > RELIGHT_HSH_ORDER:  # said on fit.rti's own line: information, not a fault
            rti_why += (
                f" ({FIT_MINIMUMS.hsh(order)} terms: RTIViewer views them; relight's .rti "
                "converter and viewer, webGLRtiMaker (the WebRTIViewer's converter) and JedMills' "
                "RTIViewer know HSH of 4 or 9 terms only, so for relight or the web fit again "
                f"with --hsh-order {RELIGHT_HSH_ORDER}, or fit the images with relight-cli)"
            )
    elif req.write_hsh:
        skipped.append(
            f"fit.rti not written: HSH of order {order} needs at least {FIT_MINIMUMS.hsh(order)} "
            f"lights, there are {n}"
        )
    exported = {k for k in linear if k != "lambert"}  # the models written to files
    if normal_source == "lambert":
        linear["lambert"] = design_matrix("lambert", lights)
    if normal_source == "ptm" and "ptm" not in linear:  # --model ptm --no-ptm: fitted, not written
        linear["ptm"] = design_matrix("ptm", lights)
    # the usable observations of the sample, only when an exported model needs their range
    obs = _usable_sample(stack) if exported else None
    if obs is not None and req.export_encoding == "srgb":  # the values the files will hold
        obs = srgb_encode(obs)
    writers: dict[str, Any] = {}
    normals = albedo = None
    try:
        for key, design in linear.items():
            ill = "refuse" if key == "lambert" else "regularise"
            w, _ = solve_matrix(design, key, ill)
            if key not in exported:
                continue
            assert obs is not None
            kind, name = (
                (exporters.PtmWriter, "fit.ptm")
                if key == "ptm"
                else (exporters.RtiWriter, "fit.rti")
            )
            lo, hi = exporters.coefficient_ranges(w @ obs, margin=0.5, scale=kind.display_scale)
            writers[key] = kind(out / name, stack.width, stack.height, lo, hi)

        if not write_normals:  # the models kept only for normals are not fitted
            normal_source = ""
            linear = {k: v for k, v in linear.items() if k in exported}
        if not req.qa:  # the QA names black and saturated images itself
            # the relighting files too: --no-normals --no-qa wrote fit.ptm from a black
            # acquisition without a word
            # each judged by what it needs (a PTM its 6 lit images, the normal maps lights
            # that determine a normal)
            written = {("fit.ptm" if k == "ptm" else "fit.rti"): k for k in exported}
            skipped += no_signal_warning(
                stack, lights, names, sample_size(stack), written, normals=write_normals
            )
        # the last use of the sample: when nothing above read it, it is streamed, never held
        ref = stack.reference_level(sample_size(stack), keep_sample=False)
        del obs
        stack.forget_samples()  # planned: the sample is not needed while the bands are fitted
        release_free_memory()
        h, wd = stack.height, stack.width
        if write_normals:
            normals = MapFile(out / "normals.npy", (h, wd, 3))
            albedo_shape = (h, wd) if stack.grey else (h, wd, stack.channels)
            albedo = MapFile(out / "albedo.npy", albedo_shape)
        rows = rows_for_budget(n, wd, stack.channels, BAND_BUDGET_BYTES)
        plan = BandPlan(
            lights=np.asarray(lights),
            linear=linear,
            normal_source=normal_source,
            tile_rows=rows,
            saturation=stack.saturation_level,
            reference_level=ref,
            grey=stack.grey,
            export_encoding=req.export_encoding,
        )
        tiles = list(row_tiles(h, rows))
        # one BLAS thread: the fit is many small products over cache-sized chunks, where
        # threaded BLAS spends more in start-up and (on a shared machine) spinning than it
        # computes, and the second core decodes/reads the next band meanwhile. A Dask runner
        # started inside reads this count (blas_threads) and fits its bands with it, so its
        # outputs stay identical.
        with warnings.catch_warnings(), threadpool_limits(limits=1, user_api="blas"):
            warnings.simplefilter("ignore", FitTrustWarning)  # issued once above, not per band
            for sl, fitted in bands(stack, plan, tiles):
                for key, writer in writers.items():
                    writer.write_rows(sl.start, fitted.coefficients[key])
                if normals is not None and albedo is not None and fitted.normals is not None:
                    normals.write_rows(sl.start, fitted.normals)
                    albedo.write_rows(sl.start, fitted.albedo)
                for category, text in fitted.warnings:  # a band fitted in another process
                    warnings.warn(text, category, stacklevel=1)
    except BaseException:
        # a failure before every band is written (a read error, a worker that cannot read,
        # Ctrl-C): no open file left to the garbage collector, and nothing half-written left
        # looking like an output (the folder was new and empty: a re-run can use it)
        for writer in writers.values():
            writer.abort()
        for fmap in (normals, albedo):
            if fmap is not None:
                fmap.discard()
        raise
    for writer in writers.values():
        files.append(writer.close())
    release_free_memory()  # the bands: the PNG buffers come next
    if normals is not None and albedo is not None:
        files += exporters.write_normal_map(out / "normals", normals.read(), npy=False)
        release_free_memory()
        files += exporters.write_albedo(out / "albedo", albedo.read(), npy=False)
    return FitResult(
        out,
        model_name,
        reason_line,
        files,
        warnings=skipped,
        normals_from=normal_source,
        rti=rti_why if f"hsh{order}" in exported else "",
        fitted=tuple(k for k in linear if k != "lambert"),
    )


def rti_order(
    stack: ImageStack, lights: np.ndarray, req: FitRequest, model_name: str, choice: Any
) -> tuple[int | None, str]:
    """fit.rti's HSH order and why (:func:`~rti_rig.app.usecases.fit_rti_order.hsh_order`),
    from the evidence this fit has: ``auto``'s model choice, or for a ``--model`` fit.rti cannot
    hold the HSH orders' own; and, where that evidence left saturated pixels out, the HSH
    orders' evidence with the clipped observations kept (not for an HSH model named by
    ``--model``: written as asked). The benchmarks call this too, so that they score the order
    the fit writes."""
    evidence = choice
    if not (req.write_hsh and not req.hsh_order):
        return hsh_order(req.hsh_order, model_name, evidence, stack.n)
    named_hsh = req.model != AUTO and model_name.startswith("hsh")
    if evidence is None and not named_hsh:
        # a model named by --model that fit.rti cannot hold: its HSH order is still measured
        evidence = hsh_evidence(stack, lights)
    clipped, share = None, 0.0
    if evidence is not None and not named_hsh and stack.saturation_level is not None:
        # the model choice's sample (cached: no second read), and how much of it clips
        values, _ = stack.pixel_sample(sample_size(stack))
        share = float(np.any(values >= stack.saturation_level, axis=(0, 2)).mean())
        if share > 0.0:  # the choice left those values out: judge the orders with them kept
            clipped = hsh_evidence(ImageStack(stack, saturation_level=math.inf), lights)
    return hsh_order(req.hsh_order, model_name, evidence, stack.n, clipped, share)


def hsh_evidence(stack: ImageStack, lights: np.ndarray) -> Any:
    """The held-out evidence of the HSH orders alone (``select_model`` over them on the fit's
    pixel sample), or None where none can be measured (fewer than 5 lights)."""
    from rti_rig.reconstruct.model_select import select_model

    try:
        return select_model(
            stack, lights, max_pixels=sample_size(stack), candidates=("hsh1", "hsh2", "hsh3")
        )
    except ReconstructionError:
        return None


#: The normal maps' estimator for the model a fit uses (``auto``'s choice or ``--model``): robust
#: photometric stereo unless the model is least-squares PS, Lambert or the PTM.
NORMALS_BY_MODEL = {"ps": "ps", "lambert": "lambert", "ptm": "ptm"}


def _model_not_written(req: FitRequest, model_name: str, normals_from_it: bool) -> str:
    """What becomes of the model used when its file is not asked for (``--no-ptm`` with a PTM,
    ``--no-hsh`` with an HSH), appended to the model's line; "" when its file is written.

    Why: ``fit --model ptm --no-ptm`` said "Model: ptm: chosen by --model" and wrote no
    fit.ptm, leaving the user to look for the PTM it named."""
    if model_name == "ptm" and not req.write_ptm:
        file, option = "fit.ptm", "--no-ptm"
    elif model_name.startswith("hsh") and not req.write_hsh:
        file, option = "fit.rti", "--no-hsh"
    else:
        return ""
    use = "the model is fitted for the normal maps only" if normals_from_it else "no file holds it"
    return f"; {file} not written ({option}): {use}"


def _normal_source(model_name: str) -> str:
    """Where the normal maps come from: the Lambert fit or the PTM's Lambertian reading when
    that is the model used — also when ``--model auto`` chose it — else robust photometric
    stereo.

    Why ``auto``'s choice is followed (tried otherwise on 2026-11-25 and measured: docs/
    reconstruction.md, "Where an auto fit's normals come from"): ``auto`` picks Lambert at 7–12
    lights both on matte objects, where robust PS gives the better normals (the simulated
    painting at 12 lights: 0.56° against Lambert's 1.48°), and on glossy metal, where robust PS
    is left with 3 observations a pixel and is far worse (the coin at 7 lights: 43.9° against
    7.2°). Neither estimator is right on both; the fit says which it used (``normals_from``)
    and ``--model robust-ps`` or ``--model ps`` asks for one.
    """
    return NORMALS_BY_MODEL.get(model_name, "ps-robust")


def auto_candidates(lights: np.ndarray) -> tuple[tuple[str, ...], str]:
    """The models ``--model auto`` chooses among on ``lights``, and why Lambert is not among
    them ("" where it is).

    Every relighting model, except on lights that cannot determine a normal: there Lambert
    (photometric stereo) is left out and auto chooses among the PTM and HSH, written
    ridge-regularised and without normal maps. Why: auto had chosen Lambert on 10 lights at
    one azimuth on the simulated tablet and refused the whole fit (exit 2), but the PTM on the
    coin and the industrial part and written their relighting files; which of the two a user
    got depended on the object, not on the lights.
    """
    from rti_rig.app.normals_determined import undetermined_normals
    from rti_rig.reconstruct.registry import RELIGHT_MODELS

    undetermined = undetermined_normals(lights, "lights of this session")
    # the same choice of models the outlook before a session reads (core.fit_minimums)
    chosen = auto_models(undetermined is None)
    return tuple(m for m in RELIGHT_MODELS if m in chosen), undetermined or ""


def _refuse_undetermined_normals(req: FitRequest, model_name: str, lights: np.ndarray) -> None:
    """Refuse, naming the CLI way out, a fit whose model is photometric stereo (``--model
    ps``, ``lambert`` or ``robust-ps``) on lights that cannot give normals.

    The solver's own refusal advised "(from Python, ill_conditioned='regularise' fits it
    regularised)", which a CLI user cannot act on. ``auto`` never gets here: on such lights it
    leaves Lambert out of its choice (:func:`auto_candidates`).
    """
    from rti_rig.app.normals_determined import relighting_models, undetermined_normals

    reason = undetermined_normals(lights, "lights of this session")
    if reason is None:
        return
    asked = f"--model auto chose {model_name}" if req.model == AUTO else f"--model {req.model}"
    n = len(lights)
    outlook = fit_outlook(n, normals_determined=False)
    # below a PTM's lights --model auto writes fit.rti alone (5) or nothing (3, 4): "--model
    # auto ... write the relighting files" had been offered there all the same
    way = (
        f"{relighting_models(n)} write the relighting files (fit.rti, fit.ptm), "
        "ridge-regularised, without normal maps"
        if outlook is None
        else f"Without normal maps, {outlook}"
    )
    raise FitInputError(
        f"{asked}, photometric stereo, but {reason}: ill-conditioned for photometric stereo. "
        f"{way}; for normals, capture again with lights at several elevations and azimuths"
    )


#: Above this :func:`~rti_rig.reconstruct.ptm.reading_bias_deg` of the lights, a PTM's normal
#: maps come from robust photometric stereo. Measured on the simulator's five scenes (docs/
#: reconstruction.md, the ptm_normals_fallback table): light sets reading 3.1-6.5° off (bands
#: below 30-45°, 6-24 lights) gave robust PS the better normals on the matte scenes (0.1-2.6°
#: against 1.7-14°) and the coin, and worse ones on the brushed-steel part by 0.3-3.7°; the
#: sets below it kept the PTM, among them 7 lights at 15/40/70° (2.5°), where robust PS was
#: 44° off on the coin, and every real layout read (1.0-2.3°).
PTM_READING_BIAS_LIMIT_DEG = 3.0


def conditioned_normal_source(source: str, lights: np.ndarray) -> tuple[str, str]:
    """The normal maps' estimator in place of ``source`` (``"ptm"`` or ``"ps-robust"``, the
    estimators a relighting model brings along), and what to tell the user.

    The PTM's Lambertian reading is only as good as the PTM: on lights its 6 terms cannot
    separate (one ring, where ``l_u^2 + l_v^2`` is constant; lights at the horizon; one
    direction repeated) the ridge-regularised PTM is biased and its reading was 22-71° off on a
    matte sphere, written as if sound. So is a PTM not regularised but over the noise-gain
    limit (lights on one side only, azimuth 0-90° at 20/45/70°: condition 40, noise gain 15.2;
    its normals were 25° off on the tablet, 57° on the coin); real light sets have gains
    0.45-2.0. There robust photometric stereo is used if the lights condition Lambert's 3 terms
    (on the tablet 0.06° on a ring at 35° and 0.16° lit from one side, against the PTM's 12.1° and
    25.0°: docs/reconstruction.md, the ptm_normals_fallback table). Lambert would be better on
    glossy metal lit from one ring and worse on a tilted object's shadows (docs/
    reconstruction.md, "No normals from a PTM"). Where they do not, no normal maps are
    written and the relighting files are, regularised as always: a PTM fit had written 71°-off
    normals, an HSH fit had been refused whole for its normals. ``--model ps``, ``lambert`` or
    ``robust-ps`` asks for normals by name and is refused instead. A PTM well conditioned on
    lights that leave the reading to extrapolate (all below 30-45°) is read off by more than
    :data:`PTM_READING_BIAS_LIMIT_DEG` and is treated the same way: its normals had been 3-14°
    off on matte scenes while the QA, judging its own photometric stereo, expected 0.1°.
    """
    from rti_rig.app.normals_determined import undetermined_normals
    from rti_rig.core.rti_bases import design_matrix
    from rti_rig.reconstruct.ptm import BIAS_PROBE_TILT_DEG, reading_bias_deg
    from rti_rig.reconstruct.solve import NOISE_GAIN_LIMIT, condition_words, solve_matrix

    undetermined = undetermined_normals(lights, "lights of this session")
    if source == "ptm":
        _, ptm = solve_matrix(design_matrix("ptm", lights), "ptm", warn=False)
        # measured only where robust PS could take over (a trusted PTM, Lambert determined)
        bias = reading_bias_deg(lights) if ptm.trusted and undetermined is None else 0.0
        if ptm.trusted and bias <= PTM_READING_BIAS_LIMIT_DEG:
            return "ptm", ""
        if ptm.trusted:
            why = (
                f"well conditioned, but its Lambertian reading is {bias:.1f}° off on these "
                f"lights (a Lambertian surface tilted up to {BIAS_PROBE_TILT_DEG:g}°, limit "
                f"{PTM_READING_BIAS_LIMIT_DEG:g}°): they leave part of the hemisphere the "
                "reading spans empty"
            )
        elif ptm.regularised:
            terms = f"its {ptm.n_coefficients} terms"
            why = (
                "ridge-regularised on these lights ("
                f"{condition_words(ptm.condition_number, ptm.cond_limit, terms)}), and its "
                "normals would be biased"
            )
        else:
            why = (
                f"ill-conditioned on these lights (noise gain {ptm.noise_gain:.3g}, limit "
                f"{NOISE_GAIN_LIMIT:g}), and its normals would be far off"
            )
        if undetermined is None:
            return "ps-robust", (
                f"normals from robust photometric stereo, not the PTM: the PTM is {why}"
            )
    elif undetermined is None:
        return source, ""
    return "", (
        f"normals.png/.npy and albedo not written: {undetermined}; add lights at other "
        "elevations and azimuths"
    )


def _usable_sample(stack: ImageStack) -> np.ndarray:
    """The pixel sample's observations (N, P·C) of the pixels with no missing or saturated
    value in any image (all of them, NaN taken as 0, when no pixel is clean)."""
    sample, _ = stack.pixel_sample(sample_size(stack))  # the sample model choice read (cached)
    obs = sample.reshape(stack.n, -1)
    keep = np.all(np.isfinite(obs), axis=0)
    if stack.saturation_level is not None:
        keep &= np.all(obs < stack.saturation_level, axis=0)
    return obs[:, keep] if keep.any() else np.nan_to_num(obs)


def local_bands(
    stack: ImageStack, plan: BandPlan, tiles: list[slice]
) -> Iterator[tuple[slice, BandFit]]:
    """The single-process runner: bands in order, the next one read (in a thread) while the
    current one is fitted."""
    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="prefetch")
    try:
        pending = pool.submit(stack.rows, tiles[0], strict=False)
        for t, sl in enumerate(tiles):
            band = pending.result()  # read while the previous band was being fitted
            if t + 1 < len(tiles):
                pending = pool.submit(stack.rows, tiles[t + 1], strict=False)
            yield sl, fit_band(band, plan)
    finally:
        pool.shutdown()


def write_qa_report(out: Path, qa: QAReport, result: FitResult) -> list[Path]:
    """``qa.json`` and a one-page ``qa.html`` with the coverage map and per-image table."""
    cov = qa.coverage.astype(np.float32)
    cov_img = cv2.applyColorMap(
        np.clip(cov / max(float(cov.max()), 1.0) * 255, 0, 255).astype(np.uint8),
        cv2.COLORMAP_VIRIDIS,
    )
    cov_img[qa.coverage < 3] = (0, 0, 255)
    if not opencv_files.imwrite(out / "qa_coverage.png", cov_img):
        # OpenCV says a failed write only by its return value: unchecked, qa.html showed a
        # map that was never written (a full disk, a folder that turned read-only)
        raise RtiRigError(
            f"could not write {shown_path(out / 'qa_coverage.png')}: check the free space and "
            "that the folder is writable, then fit again"
        )
    (out / "qa.json").write_text(strict_dumps(qa.to_json(), indent=1) + "\n", encoding="utf-8")
    rows = "\n".join(_qa_row(c) for c in qa.images)
    normals = '<img src="normals.png" width="320">' if (out / "normals.png").exists() else ""
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>rti-rig QA</title>
<style>body{{font-family:sans-serif;margin:1em}} td,th{{padding:2px 6px;font-size:12px}}
tr.bad{{background:#fdd}} .v{{font-size:20px;font-weight:bold}}</style></head><body>
<p class="v">Verdict: {html.escape(qa.verdict)}</p>
{_qa_caveats(qa)}
<p>Model: {html.escape(result.model)} — {html.escape(result.reason)}.
{_expected_error_words(qa)};
noise σ {qa.noise_sigma:.4f}; pixels lit by fewer than 3 usable images:
{qa.undercovered_fraction:.1%} (red in the coverage map).</p>
<p>{normals} <img src="qa_coverage.png" width="320"></p>
<p>Fit warnings: {html.escape("; ".join(result.warnings) or "none")}</p>
<p>How each column was judged: <b>bright-end gain</b> (the {qa.thresholds["dim_percentile"]:.0f}th
percentile of image / prediction where the recorded light falls) below
{qa.thresholds["dim_gain"]} is a misfired or dim light, the median gain is shown for reference;
<b>direction error</b> (best-fit against recorded light) above the larger of
{qa.thresholds["wrong_light_deg"]}° and {qa.thresholds["wrong_light_spread"]}× the session's
median is a wrong light, judged only on images within {qa.thresholds["misfit_limit"]:.0%} of a
Lambertian rendering; <b>drift</b> (phase correlation against the prediction, and image to
image from edges where the session's edges hold still) above
{qa.thresholds["drift_px"]} px is a move if moving the image back fits better. "not judged"
marks a check that was not made on that image.</p>
<table border=1 cellspacing=0><tr><th>image</th><th>saturated</th><th>dark</th>
<th>bright-end gain (judged)</th><th>median gain</th><th>residual</th>
<th>direction error °</th><th>drift px (x, y)</th><th>problems</th></tr>
{rows}</table>
<p>Thresholds: {html.escape(json.dumps(qa.thresholds))}</p></body></html>
"""
    (out / "qa.html").write_text(page, encoding="utf-8")
    return [out / "qa.html", out / "qa.json", out / "qa_coverage.png"]


def _expected_error_words(qa: QAReport) -> str:
    """The expected normal error as what it is: a bound from the images' noise alone.

    Why: qa.html said "Expected normal error (median, bound): 0.07°" of a 4-light session of
    the shipped simulated dome whose normals were off by 0.29° at the median and 12° at the
    90th percentile (cast shadows the Lambertian bound does not count, and one image to spare
    per pixel, so the residual the noise is read from hardly shows them)."""
    n = len(qa.images)
    spare = (
        f"; with {n} images the fit has {n - 3} to spare per pixel, so the noise read from its "
        "residual leaves them out too"
        if n <= 5
        else ""
    )
    return (
        f"Expected normal error from image noise alone (median, bound): "
        f"{qa.expected_normal_error_deg:.2f}°: cast shadows, gloss and errors in the recorded "
        f"lights come on top{spare}"
    )


def _qa_caveats(qa: QAReport) -> str:
    if not qa.caveats:
        return "<p>Every check was made on every image.</p>"
    items = "".join(f"<li>{html.escape(c)}</li>" for c in qa.caveats)
    return f"<p>Checks not made:</p><ul>{items}</ul>"


def _qa_row(c: ImageCheck) -> str:
    """One image's row: the value each decision used, or "not judged" where none was made."""
    nj = "<i>not judged</i>"
    gain = f"{c.bright_end_gain:.2f}" if c.gain_judged else nj
    median = f"{c.gain:.2f}" if np.isfinite(c.gain) else "—"
    resid = f"{c.residual:.3f}" if np.isfinite(c.residual) else "—"
    direction = f"{c.direction_error_deg:.1f}" if c.direction_judged else nj
    drift = f"{c.drift_px[0]:+.2f}, {c.drift_px[1]:+.2f}" if c.drift_judged else nj
    return (
        f"<tr{' class=bad' if c.problems else ''}><td>{html.escape(c.name)}</td>"
        f"<td>{c.saturated_fraction:.2%}</td><td>{c.dark_fraction:.1%}</td>"
        f"<td>{gain}</td><td>{median}</td><td>{resid}</td><td>{direction}</td><td>{drift}</td>"
        f"<td>{html.escape('; '.join(c.problems))}</td></tr>"
    )


#: The fewest lights the QA verdict is given for: its normal map is photometric stereo's, three
#: coefficients per pixel (``FitMinimums.normal``).
VERDICT_MIN_LIGHTS = FIT_MINIMUMS.normal


def verdict_for_session(session: Path) -> str:
    """The QA verdict line of a session folder (for ``rti-rig run``'s last line).

    A session of fewer than :data:`VERDICT_MIN_LIGHTS` lights (a test shot of one or two) is
    refused in the run's words: the fit's own refusal ended "choose a lower-order model", an
    option ``run`` does not have."""
    frames, lights, names, _ = load_acquisition(session)
    if len(lights) < VERDICT_MIN_LIGHTS:
        raise RtiRigError(
            f"the verdict's normal map needs at least {VERDICT_MIN_LIGHTS} lights and this "
            f"session has {len(lights)}; run with --lights {VERDICT_MIN_LIGHTS} or more for "
            "an RTI the verdict can judge (the images taken are kept)"
        )
    no_qa = qa_without_normals(lights, session)
    if no_qa is not None:
        raise RtiRigError(no_qa)
    # judged against the white its labels state (a replay of 12-bit data: 4095), as its fit is
    full = acquisition_full_scale(frames, names, session, None)
    qa = assess(frames, lights, names, saturation=None if full is None else float(full.level))
    _remember_pixels(frames)
    report = with_lost_files(qa, session)
    command = reshoot_in_place(session, report)
    return report.verdict + (f"; {command}" if command else "")


#: What an image's problem begins with when a reshoot with the object where it is cures it (a
#: light that did not fire, or fired as another; one frame shaken): a saturated image, a move
#: of the object part-way or a session where nothing changes would be shot the same again.
_CURED_IN_PLACE = ("misfired", "wrong light", "object or camera moved: shifted")


def reshoot_in_place(session: Path, report: Any) -> str | None:
    """The ``run --resume S --reshoot IMAGES`` that reshoots the images the verdict names
    whose every problem a reshoot in place cures (:data:`_CURED_IN_PLACE`, or brighter than
    predicted: a stray flash), with ``--reshoot-lost`` where images were lost since capture;
    None when there are none, or the session cannot reshoot one image (not completed,
    adaptive, a replayed acquisition, a camera-triggered dome). Where the verdict finds the
    lights likely wrong as a whole, no image's reshoot is offered: a dome whose layout is a
    stand-in is said to be one instead (:func:`_stand_in_said`).

    Why: the verdict said "reshoot: image_006 (misfired, no light …)" and no command did it
    (``--reshoot-lost`` takes only lost images): the user had to shoot the whole session
    again, or leave the object with a hole in its lights."""
    from rti_rig.reconstruct.qa import BRIGHTER

    # a frame delivered twice (a missed trigger, a stale frame): its verdict said "reshoot
    # it" and the command offered had left it out
    from rti_rig.reconstruct.qa_repeated import REPEATED as _CAMERA_CURED
    from rti_rig.runtime.session import read_manifest

    try:
        manifest = read_manifest(session)
    except (OSError, RtiRigError, ValueError):
        return None
    rig = manifest.get("rig") or {}
    config = rig.get("config") or {}
    dome = config.get("dome") or {}
    camera = (config.get("camera") or {}).get("device") or {}
    if getattr(report, "lp_defect", ""):
        # the .lp is the established cause (edited since capture): written again from the
        # journal, the images are as captured; a reshoot of the image under the edited line
        # had been offered beside that mend, "once what made the light wrong is mended"
        return None
    if getattr(report, "lights_likely_wrong", False):
        # one image's reshoot cures nothing when most recorded lights are wrong (the verdict
        # names none one by one for it): it had been offered all the same
        return _stand_in_said(session, dome)
    if (
        (manifest.get("runner") or {}).get("finish_reason") != "completed"
        or "adaptive" in manifest
        or rig.get("backend") == "replay"
        or "flash_sync" in dome
        # an image sequence starts again from its first file: its resume is refused
        or (camera.get("kind") == "opencv" and camera.get("backend") == "images")
    ):
        return None

    def cured(problem: str) -> bool:
        return problem.startswith((*_CURED_IN_PLACE, _CAMERA_CURED)) or problem.endswith(BRIGHTER)

    chosen = [c for c in report.reshoot if c.problems and all(map(cured, c.problems))]
    names = [Path(c.name).stem for c in chosen]
    lost = list(getattr(report, "lost_unfitted", ()) or ())
    if not names:
        return None
    words = f"rti-rig run --resume {shell_word(str(session))} --reshoot {','.join(names)}"
    words += " --reshoot-lost" if lost else ""
    # a dead or weak LED, or a wrong LED map, gives the same image again until it is mended;
    # a camera that returned an earlier frame, until its trigger is
    camera = [any(p.startswith(_CAMERA_CURED) for p in c.problems) for c in chosen]
    causes = []
    if not all(camera):
        causes.append(
            "what made the light wrong is mended (an LED that did not fire, a loose "
            "connector, a swapped LED)"
        )
    if any(camera):
        causes.append(
            "what made the camera deliver an earlier frame is mended (a missed trigger, a "
            "stale frame)"
        )
    return f"to reshoot {', '.join(names)} in place, once {' and '.join(causes)}: {words}"


def _stand_in_said(session: Path, dome: dict[str, Any]) -> str | None:
    """Why a dome session's lights may be wrong as a whole: a ``fibonacci`` layout is the
    stand-in a new dome is shot with before its LEDs are measured (docs/guide.md), and its
    sphere session's verdict then reads "lights likely wrong"; None for another layout."""
    if dome.get("layout") != "fibonacci":
        return None
    return (
        'this dome\'s layout is "fibonacci": if it stands in for LED directions not yet '
        "measured (a session of a sphere, to measure them), that is why, and nothing is to "
        "reshoot: measure them with rti-rig lights-from-sphere "
        f"{shell_word(str(session))} --sphere X,Y,R --out my_dome.lp (the sphere's centre "
        "column, row and radius in pixels)"
    )


def qa_without_normals(lights: np.ndarray, session: Path | None = None) -> str | None:
    """Why the QA cannot judge a session's images, where its lights give no normals, in words
    a command-line user can act on; None where they give normals. ``session``: the folder
    whose fit is still to be made (the run's verdict), named in the command that makes it.

    Why: the QA judges each image against a photometric-stereo fit, and the solver's refusal
    reached the verdict of a ``run --allow-no-normals`` as "(from Python,
    ill_conditioned='regularise' fits it regularised)": no option of ``rti-rig fit`` does that,
    and a QA of a regularised normal map would judge images against a guess.
    """
    from rti_rig.app.normals_determined import undetermined_normals
    from rti_rig.app.usecases.next_fit import model_for_lights

    reason = undetermined_normals(lights, "lights of this session")
    if reason is None:
        return None
    model = model_for_lights(lights)
    if session is None:
        fit = ""
    elif model is None:  # 3 such lights: no model of the fit takes them
        fit = f"; nor can `rti-rig fit` write a relighting file of {len(lights)} such lights"
    else:  # a folder that does not exist yet beside the session: FOLDER pasted made one so named
        files = "fit.rti" if model else "the relighting files"  # --model hsh1: fit.rti alone
        fit = f"; `{fit_beside(session)}{model}` still writes {files}"
    return (
        f"the QA judges every image against a normal map, and {reason}. No option of "
        f"`rti-rig fit` gives a verdict on such lights{fit}. For a verdict, capture again with "
        "lights at several elevations and azimuths"
    )


def _read_pixels(frame: Any) -> str | None:
    """The pixel checksum a TIFF frame took as the fit read it through, or None."""
    got = frame.pixel_digest if isinstance(frame, TiffRows) else None
    return None if got is None else str(got[1])


def _remember_pixels(frames: list[Any]) -> None:
    """Hand the integrity check the pixel checksums the TIFFs of ``frames`` took as they were
    read through (:attr:`TiffRows.pixel_digest`): it then reads none of them again."""
    for frame in frames:
        got = frame.pixel_digest if isinstance(frame, TiffRows) else None
        if got is not None:
            remember_pixel_digest(frame.path, *got)
