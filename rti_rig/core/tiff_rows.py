"""Rows of a TIFF on demand: a captured image read a band at a time, never whole.

A session's ``linear/*.tif`` are 16-bit, uncompressed (sessions written before 2026-11-24:
zlib-compressed in strips). A fit streams through bands of rows of all images; decoding whole
frames would hold the acquisition in memory. :class:`TiffRows` reads only the rows asked for
(uncompressed: straight from their byte offsets) or decodes only the strips that cover them
(zlib: keeping the last strip, since bands rarely align with strips), and otherwise falls back
to reading the image whole — correct for any TIFF, lean for the ones rti-rig writes. Whatever
the file's layout, the rows are (W, 3) colour or (W,) grey: planar TIFFs (Photoshop's "Per
Channel" order) are interleaved and an alpha sample is dropped, as the replay rig reads them.
"""

from __future__ import annotations

import os
import threading
import zlib
from pathlib import Path
from typing import Any

import numpy as np
import tifffile
from numpy.typing import NDArray

from rti_rig.core.errors import ImageFileError
from rti_rig.core.image_files import (
    SeveralFullSizeImages,
    colour_or_grey,
    pixels_hasher,
    tiff_is_planar,
    tiff_main_image,
    tiff_main_pixels,
)
from rti_rig.core.shell_words import shown_path

#: TIFF compression codes decoded strip by strip here: none, Adobe deflate, deflate.
_STRIPPED = {1: "none", 8: "zlib", 32946: "zlib"}


class TiffRows:
    """Read-only, array-like view of a TIFF's full-resolution image (its first page, unless a
    thumbnail comes first: :func:`~rti_rig.core.image_files.tiff_main_image`); ``obj[a:b]``
    decodes rows a..b."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        try:
            self._read_header()
        except (ImageFileError, MemoryError):
            raise
        except Exception as exc:  # tifffile raises many kinds (TiffFileError, IndexError, …)
            raise _unreadable(self.path, exc) from None
        self._full: NDArray[Any] | None = None
        self._cache: dict[int, NDArray[Any]] = {}
        self._row_shape = self.shape[1:]
        #: (the file's stat when its last row was read, :func:`pixels_sha256` of its pixels),
        #: once a pass of reads from the first row to the last, in order, found the file
        #: unchanged throughout; None until then. Why: a fit goes through every row anyway, and
        #: the session's integrity check then needs no second read of the file
        #: (:func:`rti_rig.runtime.session.remember_pixel_digest`).
        self.pixel_digest: tuple[os.stat_result, str] | None = None
        self._hash_lock = threading.Lock()
        self._hash: Any = None  # the checksum of rows 0.._hashed_to of the pass under way
        self._hashed_to = 0
        self._hash_start: tuple[int, ...] = ()

    def _read_header(self) -> None:
        with tifffile.TiffFile(self.path) as tf:
            page = tiff_main_image(tf).keyframe  # not a thumbnail in IFD0 (as the replay)
            stored = tuple(int(x) for x in page.shape)
            self._planar = tiff_is_planar(page) and len(stored) == 3
            if self._planar:  # separate planes: (samples, H, W) as stored
                stored = (*stored[1:], stored[0])
            #: colour or grey (an alpha sample dropped, planes interleaved): what a fit needs;
            #: such a TIFF is read whole, as rows cannot be taken from it in place
            self._reshaped = self._planar or (len(stored) == 3 and stored[2] != 3)
            self.shape: tuple[int, ...] = stored
            if len(stored) == 3 and stored[2] != 3:
                self.shape = stored[:2] + ((3,) if stored[2] > 3 else ())
            self.dtype = np.dtype(page.dtype)
            self.ndim = len(self.shape)
            #: the first page's ImageDescription ("" when none): what the writer said the
            #: pixels are (a session's mosaic TIFFs say so, :data:`MOSAIC_TIFF_LABEL`)
            self.description: str = str(page.description or "")
            comp = int(page.compression)
            lean = (
                comp in _STRIPPED
                and int(page.predictor) == 1
                and int(page.planarconfig) == 1
                and not self._reshaped
                and not page.is_tiled
                and self.dtype.itemsize in (1, 2)
                # a sample of 10, 12 or 14 bits is packed: its rows are no array in place
                and int(page.bitspersample) == 8 * self.dtype.itemsize
                and tf.byteorder == "<"
                and len(page.dataoffsets) >= 1
            )
            self._compressed = comp != 1
            self._offsets = list(page.dataoffsets)
            self._counts = list(page.databytecounts)
            rps = int(page.rowsperstrip) if lean else 0
            # tifffile reports rowsperstrip 0 or more than the height for a single strip
            self._rows_per_strip = min(rps, self.shape[0]) if rps > 0 else self.shape[0]
        self._lean = lean

    def __len__(self) -> int:
        return self.shape[0]

    @property
    def reads_in_place(self) -> bool:
        """True when rows are read straight from the file (uncompressed strips): nothing to
        decode, so nothing gained by decoding the file once elsewhere."""
        return self._lean and not self._compressed

    def _strip(self, k: int) -> NDArray[Any]:
        got = self._cache.get(k)
        if got is not None:
            return got
        fd = os.open(self.path, os.O_RDONLY)
        try:
            raw = os.pread(fd, self._counts[k], self._offsets[k])
        finally:
            os.close(fd)
        try:
            data = zlib.decompress(raw) if self._compressed else raw
        except zlib.error as exc:
            raise ImageFileError(
                f"{shown_path(self.path)}: strip {k} cannot be decompressed ({exc}): the file is "
                "truncated or damaged; copy it again from the original, or leave it out of the .lp"
            ) from None
        rows = len(data) // (int(np.prod(self._row_shape)) * self.dtype.itemsize)
        arr = np.frombuffer(data, dtype=self.dtype).reshape((rows, *self._row_shape))
        self._cache = {k: arr}  # bands move forward: only the last strip is worth keeping
        return arr

    def _raw_rows(self, start: int, stop: int) -> NDArray[Any]:
        """Rows of an uncompressed TIFF read from their offsets: one read per strip touched."""
        rps = self._rows_per_strip
        row_bytes = int(np.prod(self._row_shape)) * self.dtype.itemsize
        out = np.empty((stop - start, *self._row_shape), dtype=self.dtype)
        view = memoryview(out.reshape(-1).view(np.uint8))
        fd = os.open(self.path, os.O_RDONLY)
        try:
            pos = 0
            for k in range(start // rps, (stop - 1) // rps + 1):
                lo = max(start, k * rps)
                hi = min(stop, (k + 1) * rps)
                want = (hi - lo) * row_bytes
                at = self._offsets[k] + (lo - k * rps) * row_bytes
                got = os.preadv(fd, [view[pos : pos + want]], at)
                if got != want:
                    raise ImageFileError(
                        f"{shown_path(self.path)}: short read in strip {k} ({got} of {want} "
                        "bytes): the file is truncated or was changed while being read; copy it "
                        "again from the original, or leave it out of the .lp"
                    )
                pos += want
        finally:
            os.close(fd)
        return out

    def __getitem__(self, key: Any) -> NDArray[Any]:
        if not self._lean or not isinstance(key, slice):
            if self._full is None:
                try:
                    with tifffile.TiffFile(self.path) as tf:
                        full = tiff_main_pixels(tf)
                    self._full = np.ascontiguousarray(colour_or_grey(full))
                except MemoryError:
                    raise
                except Exception as exc:  # damaged data, a codec this install lacks, …
                    raise _unreadable(self.path, exc) from None
            return self._full[key]
        start, stop, step = key.indices(self.shape[0])
        if step != 1 or stop <= start:
            return self[:][key] if step != 1 else np.empty((0, *self._row_shape), self.dtype)
        self._hash_begin(start)
        if not self._compressed:
            rows = self._raw_rows(start, stop)
        else:
            rps = self._rows_per_strip
            parts = []
            for k in range(start // rps, (stop - 1) // rps + 1):
                strip = self._strip(k)
                lo = max(start - k * rps, 0)
                hi = min(stop - k * rps, strip.shape[0])
                parts.append(strip[lo:hi])
            rows = parts[0] if len(parts) == 1 else np.concatenate(parts)
        self._hash_rows(start, stop, rows)
        return rows

    def _hash_begin(self, start: int) -> None:
        """Before rows from ``start`` are read: a read of the first row starts a pass whose
        pixel checksum is taken on the way (unless one was taken already)."""
        if start != 0 or self.pixel_digest is not None:
            return
        with self._hash_lock:
            self._hash = pixels_hasher(self.shape, self.dtype)
            self._hashed_to = 0
            self._hash_start = _identity(os.stat(self.path))

    def _hash_rows(self, start: int, stop: int, rows: NDArray[Any]) -> None:
        """Rows ``start``..``stop`` just read, added to the pass's checksum when they follow
        the last rows added (any other order ends the pass without a checksum); the last row
        gives :attr:`pixel_digest` if the file did not change meanwhile."""
        with self._hash_lock:
            if self._hash is None:
                return
            if start != self._hashed_to:
                self._hash = None
                return
            self._hash.update(memoryview(np.ascontiguousarray(rows).reshape(-1).view(np.uint8)))
            self._hashed_to = stop
            if stop < self.shape[0]:
                return
            digest, self._hash = self._hash.hexdigest(), None
            st = os.stat(self.path)
            if _identity(st) == self._hash_start:  # no write, rename or utime while read
                self.pixel_digest = (st, digest)

    def __array__(self, dtype: Any = None, copy: Any = None) -> NDArray[Any]:
        full = self[0 : self.shape[0]]
        return full.astype(dtype) if dtype is not None else np.array(full)


def _identity(st: os.stat_result) -> tuple[int, ...]:
    """What changes whenever a file's content may have (its ctime moves on any write)."""
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


def _unreadable(path: Path, exc: BaseException) -> ImageFileError:
    """A TIFF tifffile cannot read, named with tifffile's reason and what to do (it had
    reached the user as a traceback). A whole TIFF of several full-size images is said as
    that: copying it again gives the same images back."""
    if isinstance(exc, SeveralFullSizeImages):
        return ImageFileError(f"{shown_path(path)}: {exc}, or leave it out of the .lp")
    return ImageFileError(
        f"{shown_path(path)}: cannot be read as a TIFF ({type(exc).__name__}: {exc}); copy it "
        "again from the original, save it again as an uncompressed or zlib/LZW 8- or 16-bit TIFF, "
        "or leave it out of the .lp"
    )
