"""Per-pixel linear relighting models and their streamed fit.

Every model here stores coefficients (p, H, W) or (p, H, W, C) — the layout of the input
images with the coefficient axis first — and relights with one weighted sum of coefficient
planes. Relit values are clamped at 0: radiance is never negative, and an unclamped low-order
fit undershoots in shadow.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.rti_bases import design_matrix
from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.solve import COND_LIMIT, FitReport, IllConditioned, solve_matrix
from rti_rig.reconstruct.stack import ImageStack, as_direction, validate_lights
from rti_rig.reconstruct.tiling import row_tiles, rows_for_budget


@runtime_checkable
class RelightModel(Protocol):
    """Anything that renders the object under a new light: fitted models, PS results."""

    @property
    def name(self) -> str: ...

    @property
    def n_coefficients(self) -> int: ...

    def relight(self, direction: ArrayLike) -> NDArray[np.float32]:
        """Image (H, W) or (H, W, C) under the unit light ``direction`` (docs/conventions.md)."""
        ...


@dataclass(frozen=True)
class LinearBasisModel:
    """Coefficients of a linear basis in light direction, per pixel, and how they were fitted."""

    coefficients: NDArray[np.float32]
    report: FitReport
    model_name: ClassVar[str] = "linear"

    @property
    def name(self) -> str:
        return self.model_name

    @property
    def n_coefficients(self) -> int:
        return int(self.coefficients.shape[0])

    @classmethod
    def design(cls, lights: ArrayLike) -> NDArray[np.float64]:
        """Design matrix (N, p) of this model for unit ``lights`` (N, 3)."""
        return design_matrix(cls.model_name, lights)

    def relight(self, direction: ArrayLike) -> NDArray[np.float32]:
        weights = self.design(as_direction(direction)[None, :])[0].astype(np.float32)
        img = np.tensordot(weights, self.coefficients, axes=(0, 0))
        return np.maximum(img, np.float32(0.0))


@dataclass(frozen=True)
class LambertModel(LinearBasisModel):
    """Unclamped Lambertian fit: coefficients are albedo × normal (3, H, W[, C])."""

    model_name: ClassVar[str] = "lambert"

    def normals(self) -> NDArray[np.float32]:
        """Unit normals (H, W, 3) with z >= 0 from ``b = albedo × normal`` (channels averaged);
        all-dark pixels get the view axis (0, 0, 1)."""
        b = self.coefficients.astype(np.float64)
        if b.ndim == 4:
            b = b.mean(axis=-1)
        b = np.moveaxis(b, 0, -1)
        b[..., 2] = np.maximum(b[..., 2], 0.0)
        norm = np.linalg.norm(b, axis=-1, keepdims=True)
        flat = np.broadcast_to(np.array([0.0, 0.0, 1.0]), b.shape)
        out = np.where(norm > 0, b / np.where(norm > 0, norm, 1.0), flat)
        return out.astype(np.float32)


def _weighted_columns(
    design: NDArray[np.float64],
    values: NDArray[np.float32],
    usable: NDArray[np.bool_],
    cond_limit: float,
) -> tuple[NDArray[np.float32], NDArray[np.bool_]]:
    """Least squares per column of ``values`` (N, K) on its ``usable`` observations only.

    Returns coefficients (p, K) and whether each column could be fitted: at least p usable
    observations whose design rows are well-conditioned (condition number of the column-scaled
    subset within ``cond_limit``); others get zeros. Columns are grouped by their pattern of
    usable observations — saturation and NaN tend to hit the same few lights over a region — so
    each distinct pattern costs one small pseudo-inverse and one matrix product.
    """
    p = design.shape[1]
    k = values.shape[1]
    coef = np.zeros((p, k), dtype=np.float32)
    ok = np.zeros(k, dtype=bool)
    if k == 0:
        return coef, ok
    packed = np.packbits(usable.T, axis=1)  # (K, ceil(N/8))
    keys = np.ascontiguousarray(packed).view(np.dtype((np.void, packed.shape[1])))[:, 0]
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    order = np.argsort(inverse, kind="stable")
    bounds = np.searchsorted(inverse[order], np.arange(first.size + 1))
    for u, j in enumerate(first):
        cols = order[bounds[u] : bounds[u + 1]]
        rows = np.flatnonzero(usable[:, j])
        if rows.size < p:
            continue
        sub = design[rows]
        norms = np.linalg.norm(sub, axis=0)
        norms = np.where(norms > 1e-12, norms, 1.0)
        uu, sv, vt = np.linalg.svd(sub / norms, full_matrices=False)
        if sv[-1] <= 0 or sv[0] / sv[-1] > cond_limit:
            continue
        w = (vt.T / sv) @ uu.T / norms[:, None]
        # in float64, rounded on assignment: a group's column count depends on the band, and a
        # float32 product's last bit on the column count (see fit_coefficients)
        coef[:, cols] = w @ values[np.ix_(rows, cols)].astype(np.float64)
        ok[cols] = True
    return coef, ok


#: columns (pixel values) per float64 product in :func:`fit_coefficients`: the float64 copy
#: of a slice, not of the whole band or pixel sample (which model choice fits at once)
PRODUCT_COLUMNS = 8192


def fit_coefficients(
    images: Any,
    design: NDArray[np.float64],
    model: str,
    *,
    tile_rows: int | None = None,
    ill_conditioned: IllConditioned = "regularise",
    cond_limit: float = COND_LIMIT,
    out: NDArray[Any] | None = None,
    saturation: float | None = None,
    basis: str | None = None,
) -> tuple[NDArray[Any], FitReport]:
    """Fit ``design`` to every pixel of ``images``, a band of rows at a time.

    Returns coefficients (p, H, W) or (p, H, W, C) float32 and the fit report. The float32
    working set is one band (see :mod:`rti_rig.reconstruct.tiling`); the solve matrix is
    computed once in float64 and applied in float64 to the float32 band, rounded to float32
    (so that a pixel's coefficients do not depend on the band's width). ``out`` (same shape)
    receives the coefficients instead of a new array: a ``numpy.memmap`` keeps a 24-megapixel
    HSH3 fit (4.6 GB of float32 colour coefficients) out of memory.

    Saturated (at or above ``saturation``, default the stack's level) and NaN observations are
    excluded: a pixel value with any of them is fitted by least squares on its other
    observations, or left at 0 and counted as unfitted when too few remain. The report counts
    both.
    """
    stack = ImageStack(images, saturation_level=saturation)
    if design.shape[0] != stack.n:
        raise ValueError(f"design has {design.shape[0]} rows for {stack.n} images")
    w, report = solve_matrix(design, model, ill_conditioned, cond_limit, basis=basis)
    p = w.shape[0]
    rows = tile_rows or rows_for_budget(stack.n, stack.width, stack.channels)
    shape = (p, stack.height, stack.width) + (() if stack.grey else (stack.channels,))
    if out is not None and out.shape != shape:
        raise ReconstructionError(f"out has shape {out.shape}, the coefficients need {shape}")
    coef = np.empty(shape, dtype=np.float32) if out is None else out
    missing = unfitted = 0
    sat = stack.saturation_level
    for sl in row_tiles(stack.height, rows):
        band = stack.rows(sl, strict=False, copy=False)  # (N, r, W, C), maybe a view
        r = band.shape[1]
        flat = band.reshape(stack.n, -1)
        target = coef[:, sl].reshape(p, -1)  # a view for in-memory outputs: written in place
        direct = np.may_share_memory(target, coef)
        # summed in float64, then rounded to float32: a float32 product's last bit depends on
        # how BLAS blocks the band's columns (its width), and the exported 8-bit coefficients
        # of a pixel must not depend on the band size or the process that fitted it (a pixel
        # near a rounding boundary flipped a byte of fit.ptm between band sizes)
        tile = target if direct else np.empty((p, flat.shape[1]), dtype=np.float32)
        for c0 in range(0, flat.shape[1], PRODUCT_COLUMNS):  # float64 a slice at a time
            cols = slice(c0, c0 + PRODUCT_COLUMNS)
            tile[:, cols] = w @ flat[:, cols].astype(np.float64)
        # NaN/inf in an observation propagates into its column's coefficients: find them there
        # (one sum over the p rows, not N); saturation needs one max-reduction over the band
        with np.errstate(invalid="ignore", over="ignore"):
            bad_cols = ~np.isfinite(np.add.reduce(tile, axis=0))
        hit = stack.suspect_columns(flat)
        if hit is not None:
            bad_cols |= hit
        if bad_cols.any():
            cols = np.flatnonzero(bad_cols)
            vals = flat[:, cols]
            usable = np.isfinite(vals)
            if sat is not None:
                with np.errstate(invalid="ignore"):
                    usable &= vals < np.float32(sat)
            vals = np.where(usable, vals, np.float32(0.0))
            sub, ok = _weighted_columns(design, vals, usable, cond_limit)
            tile[:, cols] = sub
            missing += cols.size
            unfitted += int((~ok).sum())
        if not direct:
            tile = tile.reshape(p, r, stack.width, stack.channels)
            coef[:, sl] = tile[..., 0] if stack.grey else tile
    if missing:
        report = replace(report, pixels_with_missing=missing, pixels_unfitted=unfitted)
    return coef, report


def fit_lambert(
    images: Any,
    lights: ArrayLike,
    *,
    tile_rows: int | None = None,
    ill_conditioned: IllConditioned = "refuse",
    out: NDArray[Any] | None = None,
    saturation: float | None = None,
) -> LambertModel:
    """Least-squares Lambertian model (no shadow handling): the lowest-order relighting model.

    Refuses ill-conditioned light sets by default, judged like photometric stereo judges them
    (over the hemisphere: near-coplanar lights, or a cap near the zenith): its coefficients are
    read as normals, and a regularised normal is biased towards the well-lit plane.
    """
    stack = ImageStack(images)
    lt = validate_lights(lights, stack.n)
    coef, report = fit_coefficients(
        stack,
        LambertModel.design(lt),
        "lambert",
        tile_rows=tile_rows,
        ill_conditioned=ill_conditioned,
        out=out,
        saturation=saturation,
    )
    return LambertModel(coef, report)
