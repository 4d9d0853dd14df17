"""Polynomial texture maps (Malzbender, Gelb, Wolters 2001): 6 coefficients per pixel.

``I(l) = a0 l_u^2 + a1 l_v^2 + a2 l_u l_v + a3 l_u + a4 l_v + a5`` with ``(l_u, l_v)`` the light's
projection on the image plane, ``(l_x, l_y)`` in the docs/conventions.md frame. The fit needs
lights at two or more elevations: on a single ring ``l_u^2 + l_v^2`` is constant and the design is
singular (regularised or refused, see :mod:`rti_rig.reconstruct.solve`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.reconstruct.linear_model import LinearBasisModel, fit_coefficients
from rti_rig.reconstruct.solve import COND_LIMIT, IllConditioned
from rti_rig.reconstruct.stack import ImageStack, channel_mean, validate_lights


@dataclass(frozen=True)
class PTMModel(LinearBasisModel):
    """PTM coefficients (6, H, W[, C]) in Malzbender's order a0..a5."""

    model_name: ClassVar[str] = "ptm"

    def normals(self, tile_rows: int = 256) -> NDArray[np.float32]:
        """Normals (H, W, 3) by a Lambertian reading of the PTM, a band of rows at a time.

        The PTM is evaluated at :data:`VIRTUAL_LIGHTS` directions and photometric stereo is
        solved on those virtual images: first on every direction the PTM predicts lit (above
        :data:`LIT_FRACTION` of the pixel's brightest), then again without the directions
        within :data:`TERMINATOR_COS` of the shadow line of that first normal, where the
        quadratic smooths the attached shadow. The quadratic's maximum (Malzbender §3.2, kept
        as :meth:`normals_from_maximum`) is biased by design: attached shadows and highlights
        flatten and shift it (28–46° on a glossy sphere where this reading gives 2–14°,
        docs/reconstruction.md). Colour coefficients are averaged first; pixels the PTM
        predicts dark everywhere get the view axis.
        """
        # local import: photometric_stereo's per-pixel solver, shared rather than repeated
        from rti_rig.reconstruct.normal_equations import solve_weighted

        c = self.coefficients
        h, w = c.shape[1], c.shape[2]
        dirs = _virtual_lights()
        basis = self.design(dirs).astype(np.float32)  # (K, 6)
        out = np.empty((h, w, 3), dtype=np.float32)
        for start in range(0, h, tile_rows):
            sl = slice(start, min(h, start + tile_rows))
            band = np.asarray(c[:, sl], dtype=np.float32)
            if band.ndim == 4:
                band = channel_mean(band)
            r = band.shape[1]
            vals = basis @ band.reshape(6, -1)  # (K, P)
            peak = vals.max(axis=0)
            g = np.ascontiguousarray(vals.T)  # (P, K)
            lit = g > LIT_FRACTION * np.maximum(peak, 0.0)[:, None]
            lit &= (peak > 0)[:, None]
            b, ok = solve_weighted(g, lit, dirs, 1e3)
            norm = np.linalg.norm(b, axis=1, keepdims=True)
            n = np.where(norm > 0, b / np.where(norm > 0, norm, 1.0), 0.0)
            keep = lit & ((n @ dirs.T) > TERMINATOR_COS)
            b2, ok2 = solve_weighted(g, keep, dirs, 1e3)
            b = np.where(ok2[:, None], b2, b)
            ok = ok | ok2
            b[:, 2] = np.maximum(b[:, 2], 0.0)
            norm = np.linalg.norm(b, axis=1, keepdims=True)
            good = ok & (norm[:, 0] > 0)
            n = np.where(good[:, None], b / np.where(norm > 0, norm, 1.0), [0.0, 0.0, 1.0])
            out[sl] = n.reshape(r, w, 3)
        return out

    def normals_from_maximum(self) -> NDArray[np.float32]:
        """Normals (H, W, 3) from the maximum of the biquadratic (Malzbender §3.2).

        The maximum ``(l_u0, l_v0)`` of the luminance polynomial is taken as the normal's
        projection; where the quadratic has no maximum inside the unit disc (not concave, or
        outside) the normal is clipped to the disc edge along the same direction, or set to
        the view axis when there is no maximum at all. Colour coefficients are averaged first.
        Biased by design on real surfaces; kept for comparison (see :meth:`normals`).
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


#: Virtual light directions at which :meth:`PTMModel.normals` reads the PTM.
VIRTUAL_LIGHTS = 64
#: A virtual observation counts as lit above this fraction of the pixel's brightest.
LIT_FRACTION = 0.05
#: Second pass: directions closer than this cosine to the first normal's shadow line are dropped.
TERMINATOR_COS = 0.3


def _virtual_lights() -> NDArray[np.float64]:
    """Fibonacci hemisphere above 15° elevation: where a PTM's fitting lights usually are."""
    n = VIRTUAL_LIGHTS
    i = np.arange(n) + 0.5
    zmin = np.sin(np.radians(15.0))
    z = 1.0 - (1.0 - zmin) * i / n
    rr = np.sqrt(1.0 - z * z)
    phi = i * np.pi * (3.0 - np.sqrt(5.0))
    return np.stack([rr * np.cos(phi), rr * np.sin(phi), z], axis=1)


#: The tilts (degrees from the view axis) of the Lambertian surface :func:`reading_bias_deg`
#: reads back: the relief of the paintings, tablets and coins RTI is shot of.
BIAS_PROBE_TILT_DEG = 30.0


def reading_bias_deg(lights: ArrayLike) -> float:
    """How far off (mean degrees) :meth:`PTMModel.normals` reads a noiseless Lambertian
    surface tilted 0-30° (every 5°, 12 azimuths, attached shadows kept) lit from ``lights``:
    a property of the lights alone, measured by fitting the PTM to that surface and reading it.

    Why: the reading evaluates the PTM over the hemisphere above 15°, so on lights that leave
    part of it empty it reads an extrapolated quadratic. Lights at 10° and 25° (16 of the
    shipped dome's, ``--max-elevation-deg 30``) give a PTM that is well conditioned yet reads
    5.6° off here, and the fit's normals were 3.7° off on the simulated painting and 12° on the
    tilted plane while robust photometric stereo was 0.3° and 0.2° off (docs/reconstruction.md,
    the ptm_normals_fallback table). Real full layouts read 1.0° (the shipped dome's 48) to
    2.3° (18 lights of a real acquisition).
    """
    lt = validate_lights(lights)
    tilt = np.radians(np.linspace(0.0, BIAS_PROBE_TILT_DEG, 7))
    az = np.radians(np.arange(0.0, 360.0, 30.0))
    t, a = (x.ravel() for x in np.meshgrid(tilt, az))
    truth = np.stack([np.sin(t) * np.cos(a), np.sin(t) * np.sin(a), np.cos(t)], axis=-1)
    images = np.maximum(lt @ truth.T, 0.0).astype(np.float32)[:, None, :]  # (N, 1, P)
    with warnings.catch_warnings():  # a probe of the lights: the fit itself says its warnings
        warnings.simplefilter("ignore")
        read = fit_ptm(images, lt).normals()[0].astype(np.float64)
    cos = np.clip(np.sum(read * truth, axis=-1), -1.0, 1.0)
    return float(np.degrees(np.arccos(cos)).mean())


def fit_ptm(
    images: Any,
    lights: ArrayLike,
    *,
    tile_rows: int | None = None,
    ill_conditioned: IllConditioned = "regularise",
    cond_limit: float = COND_LIMIT,
    out: NDArray[Any] | None = None,
    saturation: float | None = None,
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
        saturation=saturation,
    )
    return PTMModel(coef, report)
