"""The float maps of `rti-rig fit` (``normals.npy``, ``albedo.npy``) written a band at a time.

A fit computes its normal and albedo maps band by band. They used to be written into a
writable ``numpy.memmap`` of the ``.npy``: every page written there is part of the process's
resident set (``ru_maxrss`` counts file-backed pages) until it is flushed and dropped, and a
synchronous flush per band cost more than the band's fit, so pages piled up between flushes
(16 MB of them, at 2.5 MP a sixth of the memory relight's normals fit uses). :class:`MapFile`
writes each band with ``pwrite`` instead: the bytes go to the page cache, which is not the
process's memory, and nothing needs flushing. The header is written by ``numpy.lib.format``
(format 1.0, what ``np.save`` and ``open_memmap`` write for these shapes), so the file's bytes
are what the memmap wrote.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray


class MapFile:
    """A float32 ``.npy`` of ``shape`` (rows first), filled by :meth:`write_rows`."""

    def __init__(self, path: Path, shape: tuple[int, ...]) -> None:
        self.path = path
        self.shape = tuple(int(x) for x in shape)
        self.dtype = np.dtype(np.float32)
        header = {
            "descr": np.lib.format.dtype_to_descr(self.dtype),
            "fortran_order": False,
            "shape": self.shape,
        }
        with open(path, "wb") as fh:  # the header numpy's np.save / open_memmap write
            np.lib.format.write_array_header_1_0(fh, header)
            self._offset = fh.tell()  # where row 0 starts
            fh.truncate(self._offset + int(np.prod(self.shape, dtype=np.int64)) * 4)
        self._row_bytes = int(np.prod(self.shape[1:], dtype=np.int64)) * self.dtype.itemsize
        self._fd: int | None = os.open(path, os.O_WRONLY)

    def write_rows(self, top: int, rows: NDArray[Any]) -> None:
        """Rows ``top .. top + len(rows)`` of the map (converted to float32, C order)."""
        if self._fd is None:
            raise ValueError(f"{self.path} is closed")
        data = np.ascontiguousarray(rows, dtype=self.dtype)
        if data.shape[1:] != self.shape[1:] or top < 0 or top + len(data) > self.shape[0]:
            raise ValueError(f"rows {data.shape} at {top} do not fit a map of {self.shape}")
        view = memoryview(data.reshape(-1).view(np.uint8))
        at = self._offset + top * self._row_bytes
        while view:  # pwrite may write less than asked (e.g. interrupted)
            done = os.pwrite(self._fd, view, at)
            view, at = view[done:], at + done

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def discard(self) -> None:
        """A fit that failed: close and remove the map (a partly written ``.npy`` is a valid
        file that would look like an output)."""
        self.close()
        self.path.unlink(missing_ok=True)

    def __del__(self) -> None:  # a fit that failed half-way drops its maps unclosed
        self.close()

    def read(self) -> np.memmap:
        """The written map, read-only and file-backed (readers drop its pages as they go,
        e.g. :func:`rti_rig.reconstruct.exporters.write_normal_map`)."""
        self.close()
        return np.load(self.path, mmap_mode="r")
