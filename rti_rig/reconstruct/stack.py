"""Images and lights as the fitting code sees them, checked once at the edge.

Images arrive as one array (N, H, W) or (N, H, W, C) — possibly a ``numpy.memmap`` — or as a
sequence of N arrays (H, W) / (H, W, C), e.g. the ``uint16`` pixels of captured frames, or
row-readable array-likes such as :class:`rti_rig.core.tiff_rows.TiffRows` (files read a band at
a time). Nothing
here converts the whole stack: :meth:`ImageStack.rows` converts one band of rows to float32 on
demand, so a stack larger than memory can be fitted from a memmap or from frames kept as
``uint16``.

Integer images are scaled to [0, 1] by ``scale`` (default 1 / the dtype's maximum, or
1 / white level via :func:`stack_from_frames`); float images are taken as linear values as given.
Saturation: integer images saturate at their top code value; float images have no known
saturation level unless one is given (``saturation_level``, or ``saturation=`` of every fit),
and then every fit honours it. NaN and infinite values are missing observations.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.percentile import TopValues, percentile, values_needed
from rti_rig.reconstruct.signal_check import sample_grid

#: A light may dip this far below the horizon (z) through calibration noise; it is clipped to 0.
HORIZON_TOLERANCE = 1e-6
#: Light vectors whose length differs from 1 by more than this are rejected, not renormalised:
#: such a file holds positions or a wrong unit, and silently fixing it would hide that.
UNIT_TOLERANCE = 0.05


class ImageStack:
    """Read-only view of N linear images, read a band of rows at a time as float32.

    ``saturation_level`` (in scaled units) marks clipped observations; integer images default
    to their top code value, float images to None (unknown).

    ``grey`` is True when the images have no channel axis; fitted outputs then have none either.
    """

    def __init__(
        self, images: Any, scale: float | None = None, saturation_level: float | None = None
    ) -> None:
        if isinstance(images, ImageStack):
            self._frames: Sequence[Any] | None = images._frames
            self._array = images._array
            self._lazy = images._lazy
            self._samples = images._samples
            self.n, self.height, self.width = images.n, images.height, images.width
            self.channels, self.grey = images.channels, images.grey
            self.dtype, self.scale = images.dtype, images.scale if scale is None else scale
            self.saturation_level = (
                images.saturation_level if saturation_level is None else saturation_level
            )
            return
        if isinstance(images, np.ndarray):
            if images.ndim not in (3, 4):
                raise ReconstructionError(
                    f"images must have shape (N, H, W) or (N, H, W, C), got {images.shape}"
                )
            self._array: NDArray[Any] | None = images
            self._frames = None
            self._lazy = False
            shape = images.shape[1:]
            dtype = images.dtype
        elif isinstance(images, Sequence) and len(images) > 0:
            arrays = [im if _row_readable(im) else np.asarray(im) for im in images]
            shape = arrays[0].shape
            for i, a in enumerate(arrays):
                if a.shape != shape:
                    raise ReconstructionError(
                        f"image {i} has shape {a.shape}, image 0 has {shape}: all must match"
                    )
                if a.dtype != arrays[0].dtype:
                    raise ReconstructionError(
                        f"image {i} has dtype {a.dtype}, image 0 has {arrays[0].dtype}"
                    )
            if len(shape) not in (2, 3):
                raise ReconstructionError(f"each image must be (H, W) or (H, W, C), got {shape}")
            self._array = None
            self._frames = arrays
            self._lazy = any(_row_readable(a) for a in arrays)
            dtype = arrays[0].dtype
        else:
            raise ReconstructionError("images must be an array (N, H, W[, C]) or a list of images")
        if not (np.issubdtype(dtype, np.floating) or np.issubdtype(dtype, np.integer)):
            raise ReconstructionError(f"images must be numeric, got dtype {dtype}")
        self.n = len(images)
        self.height, self.width = int(shape[0]), int(shape[1])
        self.grey = len(shape) == 2
        self.channels = 1 if self.grey else int(shape[2])
        self.dtype = np.dtype(dtype)
        if scale is None:
            scale = 1.0 / np.iinfo(dtype).max if np.issubdtype(dtype, np.integer) else 1.0
        self.scale = float(scale)
        if saturation_level is None and np.issubdtype(dtype, np.integer):
            saturation_level = float(np.iinfo(dtype).max) * self.scale
        #: Scaled value at or above which an observation is saturated (None: unknown).
        self.saturation_level = saturation_level
        self._samples: dict[int, tuple[NDArray[np.float32], NDArray[np.intp]]] = {}
        if self.height < 1 or self.width < 1 or self.channels < 1:
            raise ReconstructionError(f"images are empty: shape {shape}")

    def rows(
        self,
        sl: slice,
        indices: ArrayLike | None = None,
        *,
        strict: bool = True,
        copy: bool = True,
    ) -> NDArray[np.float32]:
        """Band of rows ``sl`` of images ``indices`` (default all) as float32 (n, r, W, C).

        ``strict`` refuses NaN or infinity; the fits read with ``strict=False`` and treat such
        values as missing observations (see :meth:`unusable`), so that one bad pixel, masked
        or not, never aborts a whole fit. ``copy=False`` may return a view of float32 input
        (no conversion needed): the caller must not write into it.
        """
        idx = np.arange(self.n) if indices is None else np.asarray(indices)
        if self._array is not None:
            band = np.asarray(self._array[:, sl] if indices is None else self._array[idx, sl])
        else:
            assert self._frames is not None
            frames = self._frames
            first = np.asarray(frames[int(idx[0])][sl]) if len(idx) else None
            if first is None:
                band = np.empty((0, 0, self.width), dtype=self.dtype)
            else:
                # converted straight into the float32 band: no stacked integer copy
                out = np.empty((len(idx), *first.shape), dtype=np.float32)

                def put(j: int) -> None:
                    frame = frames[int(idx[j])]
                    if j > 0 and hasattr(frame, "rows_float32"):
                        frame.rows_float32(sl, self.scale, out[j])  # e.g. 8-bit through a LUT
                        return
                    src = first if j == 0 else np.asarray(frame[sl])
                    np.multiply(src, np.float32(self.scale), out=out[j], casting="unsafe")

                if self._lazy:
                    # files decoded strip by strip: zlib releases the GIL, so decode in parallel
                    list(_reader_pool().map(put, range(len(idx))))
                else:
                    for j in range(len(idx)):
                        put(j)
                return self._finish(out, idx, sl, strict)
        out = band.astype(np.float32, copy=copy or self.scale != 1.0)
        if self.scale != 1.0:
            out *= np.float32(self.scale)
        return self._finish(out, idx, sl, strict)

    def _finish(
        self, out: NDArray[np.float32], idx: NDArray[Any], sl: slice, strict: bool
    ) -> NDArray[np.float32]:
        if out.ndim == 3:
            out = out[..., None]
        if strict and not np.all(np.isfinite(out)):
            bad = int(np.argwhere(~np.isfinite(out))[0][0])
            raise ReconstructionError(
                f"image {int(idx[bad])} holds NaN or infinity in rows {sl.start}:{sl.stop}; "
                "fitting needs finite linear values"
            )
        return out

    def unusable(self, band: NDArray[np.float32]) -> NDArray[np.bool_] | None:
        """Observations of ``band`` a fit must not use: NaN/infinite, or at or above the
        saturation level; None when every observation is usable (the fast path). Read-only:
        callers zero the unusable values in their own copy."""
        bad = ~np.isfinite(band)
        if self.saturation_level is not None:
            with np.errstate(invalid="ignore"):
                bad |= band >= np.float32(self.saturation_level)
        if not bad.any():
            return None
        return bad

    def suspect_columns(self, flat: NDArray[np.float32]) -> NDArray[np.bool_] | None:
        """Columns of ``flat`` (N, K) holding a saturated value, by one max-reduction (no
        temporary of the band's size); None when the level is unknown or nothing reaches it.
        Non-finite values are found by the caller from its results (NaN propagates)."""
        if self.saturation_level is None:
            return None
        with np.errstate(invalid="ignore"):
            hit = np.max(flat, axis=0) >= np.float32(self.saturation_level)
        return hit if hit.any() else None

    def _sample_grid(self, max_pixels: int) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
        """Rows and columns of the regular grid of at most ``max_pixels`` pixels."""
        return sample_grid(self.height, self.width, max_pixels)

    def _sample_rows(
        self, rows: NDArray[np.intp], cols: NDArray[np.intp]
    ) -> Iterator[NDArray[np.float32]]:
        """The grid's values of a file-backed stack, one sampled row at a time (N, cols, C)."""
        for r in rows:
            band = self.rows(slice(int(r), int(r) + 1), strict=False)  # (N, 1, W, C)
            yield band[:, 0, cols, :]

    def pixel_sample(self, max_pixels: int) -> tuple[NDArray[np.float32], NDArray[np.intp]]:
        """A regular grid of at most ``max_pixels`` pixels: values (N, P, C) and flat indices.

        A strided grid rather than a random draw, so that the sample (and a model choice made
        on it) is reproducible and touches every part of the image.
        """
        cached = self._samples.get(max_pixels)
        if cached is not None:  # a file-backed stack pays one decode pass per sample
            return cached
        rows, cols = self._sample_grid(max_pixels)
        if self._array is not None or not self._lazy:
            # one gather of the grid, not a float band per sampled row
            if self._array is not None:
                # the grid is a strided slice when both axes are sampled regularly
                if (
                    rows.size > 1
                    and cols.size > 1
                    and np.ptp(np.diff(rows)) == 0
                    and np.ptp(np.diff(cols)) == 0
                ):
                    r0, rs, c0, cs = rows[0], rows[1] - rows[0], cols[0], cols[1] - cols[0]
                    grid = np.asarray(
                        self._array[:, r0 : rows[-1] + 1 : rs, c0 : cols[-1] + 1 : cs]
                    )
                else:
                    grid = np.asarray(self._array[:, rows[:, None], cols[None, :]])
            else:
                assert self._frames is not None
                grid = np.stack([np.asarray(f)[rows[:, None], cols[None, :]] for f in self._frames])
            values = grid.astype(np.float32).reshape(self.n, rows.size * cols.size, -1)
            if self.scale != 1.0:
                values *= np.float32(self.scale)
        else:
            # filled row by row into one array: a list of parts then concatenated would hold
            # the sample twice (2 × 22 MB at 72 images × 2.5 MP)
            values = np.empty((self.n, rows.size * cols.size, self.channels), np.float32)
            for k, part in enumerate(self._sample_rows(rows, cols)):
                values[:, k * cols.size : (k + 1) * cols.size] = part
        flat = (rows[:, None] * self.width + cols[None, :]).ravel()
        self._samples[max_pixels] = (values, flat)
        return values, flat

    def reference_level(self, max_pixels: int = 10_000, keep_sample: bool = True) -> float:
        """A robust "bright" level of the stack: the 99th percentile of a pixel sample.

        Thresholds (dark, highlight floor) are fractions of it, so they follow the exposure.
        ``keep_sample=False`` (a caller with no further use for the sample): a file-backed
        stack whose sample is not cached streams it, keeping only its top 1 % — the same
        number without the sample in memory (22 MB at 72 images × 2.5 MP).
        """
        if not keep_sample and max_pixels not in self._samples and self._lazy:
            rows, cols = self._sample_grid(max_pixels)
            top = TopValues(values_needed(self.n * rows.size * cols.size * self.channels, 99.0))
            for part in self._sample_rows(rows, cols):
                top.add(part)
            level = top.percentile(99.0)
        else:
            values, _ = self.pixel_sample(max_pixels)
            level = percentile(values, 99.0)
        return level if level > 0 else 1.0

    def forget_samples(self) -> None:
        """Drop the cached pixel samples (a fit holds them only while it plans: at 72 images
        × 2.5 MP the sample is 22 MB, a fifth of the memory a normals fit may use)."""
        self._samples.clear()


_POOL: ThreadPoolExecutor | None = None


def _reader_pool() -> ThreadPoolExecutor:
    """Threads that decode file-backed frames (one per core)."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=os.cpu_count() or 2, thread_name_prefix="rows")
    return _POOL


def _row_readable(obj: Any) -> bool:
    """An array-like read a band of rows at a time (``shape``, ``dtype``, ``obj[a:b]``), e.g.
    :class:`rti_rig.core.tiff_rows.TiffRows`: kept as is, never read whole."""
    return (
        not isinstance(obj, np.ndarray)
        and hasattr(obj, "shape")
        and hasattr(obj, "dtype")
        and hasattr(obj, "__getitem__")
    )


def stack_from_frames(frames: Sequence[Any]) -> ImageStack:
    """Stack of captured :class:`rti_rig.core.devices.Frame` objects, kept as uint16 (no float
    copy).

    Values are scaled by 1 / white level, so the stack's saturation level is 1.0.
    """
    if not frames:
        raise ReconstructionError("no frames to reconstruct from")
    levels = {int(f.white_level) for f in frames}
    if len(levels) != 1:
        raise ReconstructionError(f"frames have different white levels {sorted(levels)}")
    white = levels.pop()
    if white <= 0:
        raise ReconstructionError(f"frame white level must be positive, got {white}")
    return ImageStack([f.pixels for f in frames], scale=1.0 / white, saturation_level=1.0)


def validate_lights(lights: ArrayLike, n_images: int | None = None) -> NDArray[np.float64]:
    """Unit light directions (N, 3) on the upper hemisphere, checked and renormalised.

    Rejects a wrong shape, a count that disagrees with the images, NaN, zero or far-from-unit
    vectors, and lights below the object plane, naming the light.
    """
    arr = np.asarray(lights, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ReconstructionError(f"lights must have shape (N, 3), got {arr.shape}")
    if n_images is not None and arr.shape[0] != n_images:
        raise ReconstructionError(
            f"{arr.shape[0]} light directions for {n_images} images: they must pair one to one"
        )
    norms = np.sqrt(np.sum(arr * arr, axis=1)) if np.isfinite(arr).all() else None
    with np.errstate(divide="ignore", invalid="ignore"):
        problems = (
            range(arr.shape[0])
            if norms is None
            else np.flatnonzero(
                (np.abs(norms - 1.0) > UNIT_TOLERANCE) | ~(arr[:, 2] / norms >= -HORIZON_TOLERANCE)
            )
        )
    for i in problems:  # only the lights that fail a check are looked at one by one
        v = arr[i]
        if not np.all(np.isfinite(v)):
            raise ReconstructionError(f"light {i} is not finite: {v.tolist()}")
        norm = float(np.linalg.norm(v))
        if abs(norm - 1.0) > UNIT_TOLERANCE:
            raise ReconstructionError(
                f"light {i} has length {norm:.4f}; light directions must be unit vectors "
                "(object to light, docs/conventions.md frame)"
            )
        if v[2] / norm < -HORIZON_TOLERANCE:
            raise ReconstructionError(
                f"light {i} = {v.tolist()} is below the object plane (z < 0); RTI lights must be "
                "on the upper hemisphere"
            )
    out = arr / np.linalg.norm(arr, axis=1, keepdims=True)
    out[:, 2] = np.clip(out[:, 2], 0.0, 1.0)
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def channel_mean(values: NDArray[Any]) -> NDArray[np.float32]:
    """Mean over the last (channel) axis as a sum of slices: numpy's ``mean(axis=-1)`` over a
    length-3 axis is a strided reduction about 10× slower than this on large bands."""
    c = values.shape[-1]
    out = np.array(values[..., 0], dtype=np.float32)
    for k in range(1, c):
        out += values[..., k]
    if c > 1:
        out *= np.float32(1.0 / c)
    return out


def as_direction(direction: ArrayLike) -> NDArray[np.float64]:
    """One light direction (3,) validated like a light of a fit."""
    return validate_lights(np.asarray(direction, dtype=np.float64).reshape(1, 3))[0]
