"""Light-direction bases of the relighting models: one row of the design matrix per light.

A per-pixel relighting model is ``I(l) = sum_k c_k * f_k(l)``; fitting every pixel is one
matrix product with the pseudo-inverse of the design matrix ``A[i, k] = f_k(l_i)``.
Lights are unit vectors (N, 3) in the frame of docs/conventions.md (x right, y up, z to the camera).

* Lambert (3): ``(l_x, l_y, l_z)``; the coefficients are albedo times normal.
* PTM (6), Malzbender et al. 2001, in their coefficient order a0..a5:
  ``(l_u^2, l_v^2, l_u l_v, l_u, l_v, 1)`` with ``(l_u, l_v) = (l_x, l_y)``.
* HSH orders 1, 2, 3 (4, 9, 16), Gautron et al. 2004: spherical harmonics re-parametrised onto
  the hemisphere by ``cos(theta~) = 2 cos(theta) - 1`` and normalised over 2 pi steradians, in
  the index order of the ``.rti`` files (RTIViewer, relight). With ``c = cos(theta) = l_z``,
  ``phi = atan2(l_y, l_x)`` and ``s = sqrt(c - c^2)``, the order-3 terms 9 and 15 use
  ``(c - c^2)^(3/2)`` — exponent **1.5**, the true HSH, as the desktop RTIViewer evaluates
  them. (Some tools write ``pow(x, 3/2)``, which integer division makes exponent 1; files fitted
  by those use that basis and will not relight identically here: docs/reconstruction.md.) The
  basis is orthonormal over the hemisphere, which a test checks by quadrature.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

# Coefficient count of each model name understood by :func:`design_matrix`: kept with the
# other light minimums, numpy-free (the command line's help reads them).
from rti_rig.core.fit_minimums import N_COEFFICIENTS

PI = np.pi


def lambert_basis(lights: ArrayLike) -> NDArray[np.float64]:
    """Design matrix (N, 3) of the Lambertian model: the light vectors themselves."""
    return np.asarray(lights, dtype=np.float64).reshape(-1, 3).copy()


def ptm_basis(lights: ArrayLike) -> NDArray[np.float64]:
    """Design matrix (N, 6) of the biquadratic PTM, Malzbender's order a0..a5."""
    lt = np.asarray(lights, dtype=np.float64).reshape(-1, 3)
    u, v = lt[:, 0], lt[:, 1]
    return np.stack([u * u, v * v, u * v, u, v, np.ones_like(u)], axis=1)


def hsh_basis(lights: ArrayLike, order: int) -> NDArray[np.float64]:
    """Design matrix (N, order^2 + 2 order + 1 → 4/9/16) of hemispherical harmonics."""
    if order not in (1, 2, 3):
        raise ValueError(f"HSH order must be 1, 2 or 3, got {order}")
    lt = np.asarray(lights, dtype=np.float64).reshape(-1, 3)
    c = np.clip(lt[:, 2], 0.0, 1.0)
    phi = np.arctan2(lt[:, 1], lt[:, 0])
    cc = np.clip(c - c * c, 0.0, None)  # sin^2(theta~) / 4 >= 0
    s = np.sqrt(cc)
    t = 2.0 * c - 1.0  # cos(theta~)
    cols = [
        np.full_like(c, 1.0 / np.sqrt(2 * PI)),
        np.sqrt(6 / PI) * np.cos(phi) * s,
        np.sqrt(3 / (2 * PI)) * t,
        np.sqrt(6 / PI) * np.sin(phi) * s,
    ]
    if order >= 2:
        cols += [
            np.sqrt(30 / PI) * np.cos(2 * phi) * (c * c - c),
            np.sqrt(30 / PI) * np.cos(phi) * t * s,
            np.sqrt(5 / (2 * PI)) * (6 * c * c - 6 * c + 1),
            np.sqrt(30 / PI) * np.sin(phi) * t * s,
            np.sqrt(30 / PI) * np.sin(2 * phi) * (c * c - c),
        ]
    if order >= 3:
        p3 = cc**1.5
        q = 5 * c * c - 5 * c + 1
        cols += [
            2 * np.sqrt(35 / PI) * np.cos(3 * phi) * p3,
            np.sqrt(210 / PI) * np.cos(2 * phi) * t * (c * c - c),
            2 * np.sqrt(21 / PI) * np.cos(phi) * s * q,
            np.sqrt(7 / (2 * PI)) * (20 * c**3 - 30 * c * c + 12 * c - 1),
            2 * np.sqrt(21 / PI) * np.sin(phi) * s * q,
            np.sqrt(210 / PI) * np.sin(2 * phi) * t * (c * c - c),
            2 * np.sqrt(35 / PI) * np.sin(3 * phi) * p3,
        ]
    return np.stack(cols, axis=1)


def design_matrix(model: str, lights: ArrayLike) -> NDArray[np.float64]:
    """Design matrix of a model named as in :data:`N_COEFFICIENTS`."""
    if model == "lambert":
        return lambert_basis(lights)
    if model == "ptm":
        return ptm_basis(lights)
    if model in ("hsh1", "hsh2", "hsh3"):
        return hsh_basis(lights, int(model[-1]))
    raise ValueError(f"unknown model '{model}'; known: {', '.join(N_COEFFICIENTS)}")
