"""Hemispherical harmonics (Gautron et al. 2004) of order 1, 2, 3: 4, 9, 16 coefficients.

The basis, its index order and the exponent 1.5 of the order-3 terms are documented in
:mod:`rti_rig.core.rti_bases` and docs/reconstruction.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.rti_bases import hsh_basis
from rti_rig.reconstruct.errors import ReconstructionError
from rti_rig.reconstruct.linear_model import fit_coefficients
from rti_rig.reconstruct.solve import COND_LIMIT, FitReport, IllConditioned
from rti_rig.reconstruct.stack import ImageStack, as_direction, validate_lights


@dataclass(frozen=True)
class HSHModel:
    """HSH coefficients ((order+1)^2, H, W[, C]) in ``.rti`` index order."""

    coefficients: NDArray[np.float32]
    report: FitReport
    order: int

    @property
    def name(self) -> str:
        return f"hsh{self.order}"

    @property
    def n_coefficients(self) -> int:
        return int(self.coefficients.shape[0])

    def relight(self, direction: ArrayLike) -> NDArray[np.float32]:
        weights = hsh_basis(as_direction(direction)[None, :], self.order)[0].astype(np.float32)
        img = np.tensordot(weights, self.coefficients, axes=(0, 0))
        return np.maximum(img, np.float32(0.0))


def fit_hsh(
    images: Any,
    lights: ArrayLike,
    order: int,
    *,
    tile_rows: int | None = None,
    ill_conditioned: IllConditioned = "regularise",
    cond_limit: float = COND_LIMIT,
    out: NDArray[Any] | None = None,
    saturation: float | None = None,
) -> HSHModel:
    """Fit HSH of ``order`` (1, 2, 3) to linear ``images``; needs N >= 4, 9, 16 lights.

    ``out``: optional array (e.g. a memmap) for the coefficients, see ``fit_coefficients``.
    """
    if order not in (1, 2, 3):
        raise ReconstructionError(
            f"HSH order must be 1, 2 or 3 (4, 9, 16 coefficients), got {order}"
        )
    stack = ImageStack(images)
    lt = validate_lights(lights, stack.n)
    coef, report = fit_coefficients(
        stack,
        hsh_basis(lt, order),
        f"hsh{order}",
        tile_rows=tile_rows,
        ill_conditioned=ill_conditioned,
        cond_limit=cond_limit,
        out=out,
        saturation=saturation,
    )
    return HSHModel(coef, report, order)
