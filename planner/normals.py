"""Relief → normals, with the relief's unknown scale resolved from the preview's own shading.

Monocular depth networks give depth only up to an affine map, and shape from shading only up to
the albedo it assumed, so the *steepness* of the relief is unknown — yet it decides how far the
normals tilt, which is what the planner cares about. The preview itself is the evidence: under
its (known or estimated) light a Lambertian surface with relief ``s·h`` shades as
``ρ·max(0, n_s · l)``; :func:`fit_relief_scale` picks the signed scale ``s`` (the sign resolves
the convex/concave ambiguity when the light is oblique) and the albedo ``ρ`` that explain the
preview best in least squares. A zenith light still constrains ``|s|`` through foreshortening
(``n·z = 1/sqrt(1 + s²|∇h|²)``), so the fit works there too; only the sign is then undecided
and the convex reading is kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.errors import ScheduleError

#: Fraction of non-finite relief values above which the relief is refused rather than repaired.
MAX_NONFINITE_FRACTION = 0.5

#: Candidate relief scales, in units of the relief's RMS slope (0 = flat).
SCALE_GRID = np.concatenate([[0.0], np.geomspace(0.02, 8.0, 36)])

#: Pixels used by the scale fit (a random subset keeps it fast on any preview size).
FIT_PIXELS = 8000


def sanitize_height(height: NDArray, source: str = "relief") -> tuple[NDArray[np.float64], int]:
    """Finite copy of ``height`` (NaN/inf replaced by the median) and how many were replaced.

    A depth network can emit NaN or infinity (overflow in fp16 exports, a division in its last
    layer); a few such pixels are repaired, a mostly broken map is an error naming ``source``.
    """
    h = np.asarray(height, dtype=np.float64)
    finite = np.isfinite(h)
    bad = int(h.size - np.count_nonzero(finite))
    if h.size == 0:
        raise ScheduleError(f"{source}: empty relief")
    if bad > MAX_NONFINITE_FRACTION * h.size:
        raise ScheduleError(
            f"{source}: {bad} of {h.size} relief values are NaN or infinite; the depth model's "
            "output is unusable (check its input size and normalisation, or omit --depth-model "
            "to use shape from shading)"
        )
    if bad:
        h = np.where(finite, h, np.median(h[finite]))
    return h, bad


def height_gradients(height: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """Slopes (dh/dx, dh/dy) in the frame of docs/conventions.md (y up: row derivative flips)."""
    if height.shape[0] < 2 or height.shape[1] < 2:
        return np.zeros_like(height), np.zeros_like(height)
    d_row, d_col = np.gradient(height)
    return d_col, -d_row


def normals_from_gradients(p: NDArray, q: NDArray, scale: float = 1.0) -> NDArray[np.float64]:
    """Unit normals (H, W, 3) of a relief with slopes ``scale·(p, q)``: ∝ (-s p, -s q, 1)."""
    n = np.stack([-scale * p, -scale * q, np.ones_like(p)], axis=-1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def normals_from_height(height: NDArray[np.float64], scale: float = 1.0) -> NDArray[np.float64]:
    """Unit normals (H, W, 3) of the relief ``scale · height`` (unit pixel pitch)."""
    p, q = height_gradients(np.asarray(height, dtype=np.float64))
    return normals_from_gradients(p, q, scale)


@dataclass(frozen=True)
class ReliefFit:
    """The relief scale the preview's shading supports, and how well it explains the preview.

    ``scale`` multiplies the relief as given (signed); ``rms_slope_deg`` is the RMS tilt of the
    resulting normals; ``explained`` is the R² of the shading fit (1 = fully explained);
    ``bright_outliers`` the fraction of pixels far brighter than the Lambertian fit predicts
    (a hint of specular highlights).
    """

    scale: float
    albedo: float
    explained: float
    rms_slope_deg: float
    bright_outliers: float


def fit_relief_scale(
    height: NDArray[np.float64],
    image: NDArray[np.float64],
    light: NDArray[np.float64],
    seed: int = 0,
) -> ReliefFit:
    """Signed relief scale and albedo that best explain ``image`` under ``light`` (see module)."""
    h = np.asarray(height, dtype=np.float64)
    img = np.asarray(image, dtype=np.float64)
    if h.shape != img.shape:
        raise ValueError(f"relief {h.shape} and image {img.shape} differ in shape")
    p, q = height_gradients(h)
    rms = float(np.sqrt(np.mean(p * p + q * q)))
    mean_i = float(img.mean())
    if rms < 1e-12 or mean_i <= 0:
        return ReliefFit(0.0, mean_i / max(float(light[2]), 1e-6), 0.0, 0.0, 0.0)
    p, q = p.ravel() / rms, q.ravel() / rms
    y = img.ravel()
    if y.size > FIT_PIXELS:
        idx = np.random.default_rng(seed).choice(y.size, FIT_PIXELS, replace=False)
        p, q, y = p[idx], q[idx], y[idx]
    lx, ly, lz = (float(v) for v in light)

    def evaluate(scales: NDArray) -> tuple[NDArray, NDArray, NDArray, int]:
        s = scales[:, None]
        shade = (-s * p * lx - s * q * ly + lz) / np.sqrt(1 + s * s * (p * p + q * q))
        shade = np.clip(shade, 0, None)
        ss = np.sum(shade * shade, axis=1)
        rho = np.where(ss > 0, np.sum(shade * y, axis=1) / np.where(ss > 0, ss, 1.0), 0.0)
        sse = np.sum((y - rho[:, None] * shade) ** 2, axis=1)
        # exact ties (a zenith light cannot tell convex from concave) go to the convex reading
        return shade, rho, sse, int(np.argmin(sse + 1e-9 * float(sse.max()) * (scales < 0)))

    scales = np.concatenate([SCALE_GRID, -SCALE_GRID[1:]])
    shade, rho, sse, best = evaluate(scales)
    if scales[best] != 0.0:  # refine between the neighbouring grid values
        ratio = float(SCALE_GRID[2] / SCALE_GRID[1])
        scales = scales[best] * np.geomspace(1 / ratio, ratio, 21)
        shade, rho, sse, best = evaluate(scales)
    sst = float(np.sum((y - y.mean()) ** 2))
    explained = 1.0 - float(sse[best]) / sst if sst > 0 else 0.0
    resid = y - rho[best] * shade[best]
    sd = float(np.std(resid))
    bright = float(np.mean(resid > 3 * sd)) if sd > 0 else 0.0
    scale = float(scales[best]) / rms
    tilt = np.arctan(abs(scales[best]) * np.hypot(p, q))
    return ReliefFit(
        scale=scale,
        albedo=float(rho[best]),
        explained=max(0.0, explained),
        rms_slope_deg=float(np.degrees(np.sqrt(np.mean(tilt * tilt)))),
        bright_outliers=bright,
    )
