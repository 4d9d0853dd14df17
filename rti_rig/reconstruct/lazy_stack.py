"""An acquisition as a lazily read, chunked ``dask.array``: bands of rows of all images.

A fit that scales out (many cores, a Dask cluster) needs the image stack as something a
scheduler can cut into tasks without anyone holding it. :func:`lazy_stack` gives a
``dask.array`` of shape ``(N, H, W, C)``, float32, scaled exactly as :meth:`ImageStack.rows`
scales it (it *is* ``ImageStack.rows``, called where the chunk is computed), chunked as bands
of ``tile_rows`` rows × all lights. Nothing is read when the array is made; computing a chunk
opens the files in the process that computes it and reads only that band's rows — 16-bit TIFFs
strip by strip through :class:`rti_rig.core.tiff_rows.TiffRows`, as the single-process fit does.

The array's graph holds only a :class:`StackSource` — file paths, the image shape, the scale
and saturation level and the function that opens one file — never pixels, so it pickles in a
few hundred bytes and a distributed worker reads the files itself: **workers must see the image
files at the same paths** (a shared filesystem). A worker that cannot read a file raises
:class:`ImageReadError` naming the file and the host.

``dask`` is imported only when :func:`lazy_stack` is called: importing this module, the rest of
the package, or running the single-process fit never loads it.
"""

from __future__ import annotations

import os
import socket
import threading
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import RtiRigError
from rti_rig.core.shell_words import shown_path
from rti_rig.core.tiff_rows import TiffRows
from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.stack import ImageStack


class ImageReadError(ReconstructionError):
    """An image of a lazily read stack could not be opened or read where a chunk is computed
    (on a Dask worker: usually a path the worker does not see)."""


#: How many opened acquisitions a process keeps (file headers and the last strip of each TIFF,
#: or the decoded pixels of formats that cannot be read by rows).
OPEN_CACHE_SIZE = 2
_OPEN: OrderedDict[tuple[Any, ...], ImageStack] = OrderedDict()
_OPEN_LOCK = threading.Lock()


def _stamps(paths: Sequence[str]) -> tuple[tuple[int, int], ...]:
    """Size and modification time of each file ((-1, -1) for one that cannot be seen: opening
    it then names it)."""
    out = []
    for p in paths:
        try:
            st = os.stat(p)
            out.append((st.st_size, st.st_mtime_ns))
        except OSError:
            out.append((-1, -1))
    return tuple(out)


@dataclass(frozen=True)
class StackSource:
    """N image files as a read-only array-like ``(N, H, W, C)`` float32 (what ``dask`` wraps).

    ``opener(path)`` returns one image as an array or a row-readable array-like (e.g.
    :class:`TiffRows`); it must be a module-level function so the source pickles by reference.
    ``scale`` and ``saturation_level`` are the stack's (:class:`ImageStack`), so that every
    process scales the values as the process that planned the fit does.
    """

    paths: tuple[str, ...]
    image_shape: tuple[int, int, int]  # H, W, C
    grey: bool
    scale: float
    saturation_level: float | None
    opener: Callable[[Path], Any] = TiffRows

    @classmethod
    def of(
        cls, paths: Sequence[Path | str], stack: ImageStack, opener: Callable[[Path], Any]
    ) -> StackSource:
        """The source of ``stack``, whose image ``i`` is the file ``paths[i]``."""
        if len(paths) != stack.n:
            raise ReconstructionError(f"{len(paths)} paths for a stack of {stack.n} images")
        return cls(
            tuple(str(Path(p).resolve()) for p in paths),
            (stack.height, stack.width, stack.channels),
            stack.grey,
            stack.scale,
            stack.saturation_level,
            opener,
        )

    # the array-like protocol dask.array.from_array needs
    @property
    def shape(self) -> tuple[int, int, int, int]:
        return (len(self.paths), *self.image_shape)

    @property
    def ndim(self) -> int:
        return 4

    @property
    def dtype(self) -> np.dtype:
        return np.dtype(np.float32)

    def opened(self) -> ImageStack:
        """The files opened in this process (cached: headers are parsed once per process)."""
        # the files' stamps are part of the key: a long-lived worker must not serve the pixels
        # of a file since rewritten at the same path (a re-exported JPEG)
        key = (
            self.paths,
            _stamps(self.paths),
            self.image_shape,
            self.scale,
            self.saturation_level,
            self.opener,
        )
        with _OPEN_LOCK:
            stack = _OPEN.get(key)
            if stack is not None:
                _OPEN.move_to_end(key)
                return stack
        frames = []
        expected = self.image_shape[:2] if self.grey else self.image_shape
        for path in self.paths:
            try:
                frame = self.opener(Path(path))
            except (OSError, ValueError, RtiRigError) as exc:  # RtiRigError: the opener's own
                raise ImageReadError(
                    f"cannot read {shown_path(path)} on host {socket.gethostname()}: {exc}"
                ) from None
            if tuple(frame.shape) != tuple(expected):
                raise ImageReadError(
                    f"{shown_path(path)} on host {socket.gethostname()} has shape "
                    f"{tuple(frame.shape)}, expected {tuple(expected)}: not the file the fit was "
                    "planned on"
                )
            frames.append(frame)
        stack = ImageStack(frames, scale=self.scale, saturation_level=self.saturation_level)
        with _OPEN_LOCK:
            _OPEN[key] = stack
            while len(_OPEN) > OPEN_CACHE_SIZE:
                _OPEN.popitem(last=False)
        return stack

    def __getitem__(self, key: Any) -> NDArray[np.float32]:
        """Values of ``self[key]``: only the rows ``key`` selects are read."""
        if not isinstance(key, tuple):
            key = (key,)
        if any(k is Ellipsis for k in key):
            at = key.index(Ellipsis)
            key = key[:at] + (slice(None),) * (5 - len(key)) + key[at + 1 :]
        key = key + (slice(None),) * (4 - len(key))
        images, rows, rest = key[0], key[1], tuple(key[2:])
        n, h = self.shape[0], self.shape[1]
        idx = np.arange(n)[images]
        scalar_image = np.ndim(idx) == 0
        wanted = np.arange(h)[rows]
        if wanted.size == 0 or np.size(idx) == 0:
            empty = np.empty(self.shape, np.float32)
            return empty[key]
        lo, hi = int(np.min(wanted)), int(np.max(wanted)) + 1
        every = isinstance(images, slice) and images.indices(n) == (0, n, 1)
        try:
            band = self.opened().rows(
                slice(lo, hi), None if every else np.atleast_1d(idx), strict=False
            )
        except (OSError, ValueError) as exc:
            raise ImageReadError(
                f"cannot read rows {lo}:{hi} of {self.paths[0]} ... on host "
                f"{socket.gethostname()}: {exc}"
            ) from None
        contiguous = isinstance(rows, slice) and rows.indices(h)[2] == 1
        out = band[(slice(None), slice(None) if contiguous else wanted - lo, *rest)]
        return out[0] if scalar_image else out


def lazy_stack(source: StackSource, tile_rows: int) -> Any:
    """``dask.array`` ``(N, H, W, C)`` float32 over ``source``, chunked as bands of
    ``tile_rows`` rows × all images (the bands :func:`rti_rig.reconstruct.tiling.row_tiles`
    gives), each read from the files when computed."""
    import dask.array as da
    from dask.base import tokenize

    if tile_rows < 1:
        raise ValueError(f"tile_rows must be at least 1, got {tile_rows}")
    n, _, w, c = source.shape
    stamp = []
    for p in source.paths:  # a rewritten file is a different array (no stale cached chunks)
        try:
            st = Path(p).stat()
            stamp.append((st.st_size, st.st_mtime_ns))
        except OSError:
            stamp.append(None)
    opener = f"{source.opener.__module__}.{source.opener.__qualname__}"
    name = "rti-stack-" + tokenize(
        source.paths, source.image_shape, source.scale, source.saturation_level, opener, stamp
    )
    return da.from_array(
        source,
        chunks=(n, tile_rows, w, c),
        name=name,
        lock=False,
        asarray=False,
        fancy=False,
        meta=np.empty((0, 0, 0, 0), np.float32),
    )
