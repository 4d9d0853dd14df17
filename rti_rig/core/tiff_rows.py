"""Rows of a TIFF on demand: a captured image read a band at a time, never whole.

A session's ``linear/*.tif`` are 16-bit, zlib-compressed in strips (tifffile's default). A fit
streams through bands of rows of all images; decoding whole frames would hold the acquisition
in memory. :class:`TiffRows` decodes only the strips that cover the rows asked for (keeping the
last strip, since bands rarely align with strips) and otherwise falls back to reading the
image whole — correct for any TIFF, lean for the ones rti-rig writes.
"""

from __future__ import annotations

import os
import zlib
from pathlib import Path
from typing import Any

import numpy as np
import tifffile
from numpy.typing import NDArray

#: TIFF compression codes decoded strip by strip here: none, Adobe deflate, deflate.
_STRIPPED = {1: "none", 8: "zlib", 32946: "zlib"}


class TiffRows:
    """Read-only, array-like view of the first page of a TIFF; ``obj[a:b]`` decodes rows a..b."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        with tifffile.TiffFile(self.path) as tf:
            page = tf.pages[0]
            self.shape: tuple[int, ...] = tuple(int(x) for x in page.shape)
            self.dtype = np.dtype(page.dtype)
            self.ndim = len(self.shape)
            comp = int(page.compression)
            lean = (
                comp in _STRIPPED
                and int(page.predictor) == 1
                and int(page.planarconfig) == 1
                and not page.is_tiled
                and self.dtype.itemsize in (1, 2)
                and tf.byteorder == "<"
                and len(page.dataoffsets) >= 1
            )
            self._compressed = comp != 1
            self._offsets = list(page.dataoffsets)
            self._counts = list(page.databytecounts)
            self._rows_per_strip = int(page.rowsperstrip) if lean else 0
        self._lean = lean
        self._full: NDArray[Any] | None = None
        self._cache: dict[int, NDArray[Any]] = {}
        self._row_shape = self.shape[1:]

    def __len__(self) -> int:
        return self.shape[0]

    def _strip(self, k: int) -> NDArray[Any]:
        got = self._cache.get(k)
        if got is not None:
            return got
        fd = os.open(self.path, os.O_RDONLY)
        try:
            raw = os.pread(fd, self._counts[k], self._offsets[k])
        finally:
            os.close(fd)
        data = zlib.decompress(raw) if self._compressed else raw
        rows = len(data) // (int(np.prod(self._row_shape)) * self.dtype.itemsize)
        arr = np.frombuffer(data, dtype=self.dtype).reshape((rows, *self._row_shape))
        self._cache = {k: arr}  # bands move forward: only the last strip is worth keeping
        return arr

    def __getitem__(self, key: Any) -> NDArray[Any]:
        if not self._lean or not isinstance(key, slice):
            if self._full is None:
                self._full = tifffile.imread(self.path)
            return self._full[key]
        start, stop, step = key.indices(self.shape[0])
        if step != 1 or stop <= start:
            return self[:][key] if step != 1 else np.empty((0, *self._row_shape), self.dtype)
        rps = self._rows_per_strip
        parts = []
        for k in range(start // rps, (stop - 1) // rps + 1):
            strip = self._strip(k)
            lo = max(start - k * rps, 0)
            hi = min(stop - k * rps, strip.shape[0])
            parts.append(strip[lo:hi])
        return parts[0] if len(parts) == 1 else np.concatenate(parts)

    def __array__(self, dtype: Any = None, copy: Any = None) -> NDArray[Any]:
        full = self[0 : self.shape[0]]
        return full.astype(dtype) if dtype is not None else np.array(full)
