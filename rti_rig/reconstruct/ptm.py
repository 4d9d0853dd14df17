"""Polynomial texture maps (Malzbender, Gelb, Wolters 2001): 6 coefficients per pixel.

``I(l) = a0 l_u^2 + a1 l_v^2 + a2 l_u l_v + a3 l_u + a4 l_v + a5`` with ``(l_u, l_v)`` the light's
projection on the image plane, ``(l_x, l_y)`` in the docs/conventions.md frame. The fit needs
lights at two or more elevations: on a single ring ``l_u^2 + l_v^2`` is constant and the design is
singular (regularised or refused, see :mod:`rti_rig.reconstruct.solve`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.reconstruct.linear_model import LinearBasisModel, fit_coefficients
from rti_rig.reconstruct.solve import COND_LIMIT, IllConditioned
from rti_rig.reconstruct.stack import ImageStack, validate_lights


@dataclass(frozen=True)
class PTMModel(LinearBasisModel):
    """PTM coefficients (6, H, W[, C]) in Malzbender's order a0..a5."""

    model_name: ClassVar[str] = "ptm"

    def normals(self) -> NDArray[np.float32]:
        """Normals (H, W, 3) from the maximum of the biquadratic (Malzbender §3.2).

        The maximum ``(l_u0, l_v0)`` of the luminance polynomial is taken as the normal's
        projection; where the quadratic has no maximum inside the unit disc (not concave, or
        outside) the normal is clipped to the disc edge along the same direction, or set to
        the view axis when there is no maximum at all. Colour coefficients are averaged first.
        """
        c = self.coefficients.astype(np.float64)
        if c.ndim == 4:
            c = c.mean(axis=-1)
        a0, a1, a2, a3, a4 = c[0], c[1], c[2], c[3], c[4]
        det = 4 * a0 * a1 - a2 * a2
        concave = (det > 1e-12) & (a0 < 0)
        safe = np.where(concave, det, 1.0)
        u = np.where(concave, (a2 * a4 - 2 * a1 * a3) / safe, 0.0)
        v = np.where(concave, (a2 * a3 - 2 * a0 * a4) / safe, 0.0)
        r = np.hypot(u, v)
        shrink = np.where(r > 0.999, 0.999 / np.maximum(r, 1e-12), 1.0)
        u, v = u * shrink, v * shrink
        z = np.sqrt(np.clip(1 - u * u - v * v, 0.0, 1.0))
        return np.stack([u, v, z], axis=-1).astype(np.float32)


def fit_ptm(
    images: Any,
    lights: ArrayLike,
    *,
    tile_rows: int | None = None,
    ill_conditioned: IllConditioned = "regularise",
    cond_limit: float = COND_LIMIT,
    out: NDArray[Any] | None = None,
) -> PTMModel:
    """Fit a PTM to linear ``images`` (N, H, W[, C]) lit from unit ``lights`` (N, 3); N >= 6.

    ``out``: optional array (e.g. a memmap) for the coefficients, see ``fit_coefficients``.
    """
    stack = ImageStack(images)
    lt = validate_lights(lights, stack.n)
    coef, report = fit_coefficients(
        stack,
        PTMModel.design(lt),
        "ptm",
        tile_rows=tile_rows,
        ill_conditioned=ill_conditioned,
        cond_limit=cond_limit,
        out=out,
    )
    return PTMModel(coef, report)
