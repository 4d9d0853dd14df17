"""Rows of a decoded image kept raw in a file: decode once, read a band of rows many times.

A fit reads an acquisition several times (a pixel sample for the model choice, the streamed
fit, the QA pass). Compressed files (JPEG, zlib TIFF) would be decoded on every pass, and
holding them decoded would hold the acquisition in memory (72 × 2.5 MP RGB is 1.1 GB as
uint16). Instead each image is decoded once and its pixels written, in C order, into a
(temporary) file; :class:`RawRows` reads rows back with one ``pread`` — from the page cache,
which is not the process's resident memory — and maps them through an optional lookup table
(e.g. sRGB 8-bit to linear 16-bit).
"""

from __future__ import annotations

import os
import tempfile
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import ImageFileError


class HasFileno(Protocol):
    def fileno(self) -> int: ...


class DecodedStore:
    """An unlinked temporary file of decoded rows, shared by the :class:`RawRows` that read it
    and closed when the last of them is released. Left to the garbage collector unclosed, a
    file is a ``ResourceWarning`` raised wherever collection happens to run — inside a later
    fit, which would record it among that fit's warnings."""

    def __init__(self) -> None:
        self.file = tempfile.TemporaryFile(prefix="rti-rig-decoded-")  # noqa: SIM115

    def fileno(self) -> int:
        return self.file.fileno()

    def __del__(self) -> None:
        self.file.close()


class RawRows:
    """Read-only, array-like (H, W[, C]) image stored raw at ``offset`` of ``file``."""

    def __init__(
        self,
        file: HasFileno,
        offset: int,
        shape: tuple[int, ...],
        stored: np.dtype[Any],
        lut: NDArray[Any] | None = None,
        name: str = "",
    ) -> None:
        self._file = file  # kept open (and alive) as long as any view of it is
        self._fd = file.fileno()
        self._offset = int(offset)
        self.shape = tuple(int(x) for x in shape)
        self.ndim = len(self.shape)
        self._stored = np.dtype(stored)
        self._lut = lut
        self.dtype = np.dtype(lut.dtype) if lut is not None else self._stored
        self.name = name
        self._row_bytes = int(np.prod(self.shape[1:])) * self._stored.itemsize
        self._float_luts: dict[float, NDArray[np.float32]] = {}

    @property
    def stored(self) -> np.dtype[Any]:
        """The pixels' type as stored (uint8 for an 8-bit image ``dtype`` reads as linear)."""
        return self._stored

    def __len__(self) -> int:
        return self.shape[0]

    def _read(self, start: int, stop: int, mapped: bool = True) -> NDArray[Any]:
        out = np.empty((stop - start, *self.shape[1:]), dtype=self._stored)
        want = out.nbytes
        if want:
            got = os.preadv(
                self._fd,
                [memoryview(out.reshape(-1).view(np.uint8))],
                self._offset + start * self._row_bytes,
            )
            if got != want:
                raise ImageFileError(
                    f"{self.name}: short read of decoded rows ({got} of {want} bytes) from the "
                    "temporary file: is the temporary folder's disk full?"
                )
        return out if self._lut is None or not mapped else self._lut[out]

    def rows_float32(self, key: slice, scale: float, out: NDArray[np.float32]) -> None:
        """Rows ``key`` × ``scale`` into ``out`` (float32): through the LUT in one step, with
        no integer copy of the band (what a fit's band reader wants)."""
        start, stop, _ = key.indices(self.shape[0])
        if self._lut is None:
            np.multiply(self._read(start, stop), np.float32(scale), out=out, casting="unsafe")
            return
        lut = self._float_luts.get(scale)
        if lut is None:
            lut = self._float_luts[scale] = self._lut.astype(np.float32) * np.float32(scale)
        np.take(lut, self._read(start, stop, mapped=False), out=out)

    def __getitem__(self, key: Any) -> NDArray[Any]:
        if isinstance(key, slice):
            start, stop, step = key.indices(self.shape[0])
            if step == 1:
                return self._read(start, max(start, stop))
        return self._read(0, self.shape[0])[key]

    def __array__(self, dtype: Any = None, copy: Any = None) -> NDArray[Any]:
        full = self._read(0, self.shape[0])
        return full.astype(dtype) if dtype is not None else full
