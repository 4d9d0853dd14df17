"""Cast shadows over a height field, for directional and point lights.

Why a sweep and not a per-pixel ray march: a pixel is in cast shadow when some point between it
and the light rises above the straight line joining them. Along one ray that test collapses to a
running extremum, so the whole image costs one resampling, one cumulative max/min and one
resampling back — O(pixels) per light instead of O(pixels × march steps).

* Directional light (azimuth ``d`` in the image plane, elevation tangent ``t``): along a line
  parallel to ``d`` with coordinate ``s`` increasing towards the light, ``p`` is shadowed iff some
  ``q`` with ``s_q > s_p`` has ``h_q - s_q·t > h_p - s_p·t``. The image is resampled on a grid
  rotated so that ``s`` runs along columns; a reversed cumulative max does the rest.
* Point light at height ``z_L`` above the foot point ``F``: rays fan out from ``F``. With ``ρ`` the
  distance from ``F``, ``q`` (closer to ``F``) occludes ``p`` iff
  ``(z_L - h_q)/ρ_q < (z_L - h_p)/ρ_p`` (the depression angle seen from the light is smaller), so
  the image is resampled on a polar grid around ``F`` and a cumulative min along ``ρ`` decides.
  This is exact for the finite light distance, not a directional approximation.

Heights and positions are in *pixel units* (unit pixel pitch), in image coordinates: ``col`` to
the right, ``row`` down. Visibility is returned as float32 in [0, 1]; the bilinear resampling back
to the image anti-aliases the shadow edge over about one pixel.

Limitations (documented in docs/simulator.md): hard shadows (point-like LEDs, no penumbra);
occluders outside the image are ignored; resampling blurs features thinner than a pixel.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Height tolerance (pixel units) below which an occluder does not count: avoids "shadow acne"
#: from interpolation on surfaces lit at nearly their own slope (where shading is ~0 anyway).
BIAS_PX = 0.02

#: Cells of a sweep's resampled grid processed at a time (rays are independent): a few MB of
#: temporaries each, where whole grids of a 24 MP frame took GB.
SWEEP_CELLS = 1 << 20

#: Above this elevation tangent (about 89.994°) no height field with finite slopes casts a
#: shadow longer than 1e-4 of its relief; treated as the zenith.
ZENITH_TAN = 1e4


def _as_height32(height: ArrayLike) -> NDArray[np.float32]:
    h = np.asarray(height)
    if h.ndim != 2:
        raise ValueError(f"height must be a 2-D array (H, W), got shape {h.shape}")
    if not np.all(np.isfinite(h)):
        raise ValueError("height contains NaN or infinity")
    return np.ascontiguousarray(h, dtype=np.float32)


def directional_visibility(
    height: ArrayLike, direction: ArrayLike, bias_px: float = BIAS_PX
) -> NDArray[np.float32]:
    """Visibility (1 lit, 0 in cast shadow) of each pixel from a directional light.

    ``direction`` is the unit vector towards the light in the frame of docs/conventions.md (x right,
    y up, z to camera). A light at the zenith casts no shadow; a light below the horizon still
    reaches slopes that face it unless something is in the way.
    """
    h = _as_height32(height)
    d = np.asarray(direction, dtype=np.float64).reshape(3)
    horiz = math.hypot(d[0], d[1])
    if horiz == 0.0 or d[2] / horiz > ZENITH_TAN:
        return np.ones(h.shape, dtype=np.float32)
    tan_el = d[2] / horiz
    # Unit azimuth in image coordinates: frame y is up, image rows run down.
    dc, dr = d[0] / horiz, -d[1] / horiz
    pc, pr = -dr, dc  # across the rays
    rows, cols = h.shape
    cc, cr = (cols - 1) / 2.0, (rows - 1) / 2.0
    ea = 0.5 * (abs((cols - 1) * dc) + abs((rows - 1) * dr)) + 1.0
    eb = 0.5 * (abs((cols - 1) * pc) + abs((rows - 1) * pr)) + 1.0
    n_a, n_b = math.ceil(2 * ea) + 1, math.ceil(2 * eb) + 1
    # Grid (column a_idx, row b_idx) -> image (col, row); a runs towards the light.
    fwd = np.array(
        [[dc, pc, cc - ea * dc - eb * pc], [dr, pr, cr - ea * dr - eb * pr]], dtype=np.float64
    )
    flags = cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP
    hs = cv2.warpAffine(h, fwd, (n_a, n_b), flags=flags, borderMode=cv2.BORDER_REPLICATE)
    inside = cv2.warpAffine(
        np.ones(h.shape, np.uint8),
        fwd,
        (n_a, n_b),
        flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_CONSTANT,
        borderValue=0,
    )
    slope = (np.arange(n_a, dtype=np.float32) - np.float32(ea)) * np.float32(tan_el)
    lit = np.empty((n_b, n_a), np.float32)
    # Lines a block at a time (each row of the grid is one line towards the light, swept on
    # its own: the same cells as from the whole grid, with a few MB of temporaries).
    step = max(1, SWEEP_CELLS // n_a)
    for b in range(0, n_b, step):
        out = inside[b : b + step] == 0
        g = hs[b : b + step] - slope
        g[out] = -np.inf
        # Highest occluder strictly nearer the light: reversed cumulative max, shifted by one.
        occ = np.empty_like(g)
        occ[:, -1] = -np.inf
        np.maximum.accumulate(g[:, :0:-1], axis=1, out=occ[:, -2::-1])
        occ -= np.float32(bias_px)
        block = lit[b : b + step]
        np.greater_equal(g, occ, out=block, casting="unsafe")
        # Cells outside the image hold no surface; call them lit so that interpolating back
        # does not darken the border pixels (a level plane must come out fully lit).
        block[out] = 1.0
        del out, g, occ
    del hs, inside
    # Back to the image: sample the lit grid at each pixel's (a_idx, b_idx).
    back = np.array(
        [[dc, dr, ea - cc * dc - cr * dr], [pc, pr, eb - cc * pc - cr * pr]], dtype=np.float64
    )
    vis = cv2.warpAffine(lit, back, (cols, rows), flags=flags, borderMode=cv2.BORDER_REPLICATE)
    return np.clip(vis, 0.0, 1.0, out=vis)


def _angular_range(fc: float, fr: float, cols: int, rows: int) -> tuple[float, float, bool]:
    """Angles (radians) subtended by the image seen from the foot point; full circle if inside."""
    if -1.0 <= fc <= cols and -1.0 <= fr <= rows:
        return -math.pi, math.pi, True
    corners = [(-0.5, -0.5), (cols - 0.5, -0.5), (-0.5, rows - 0.5), (cols - 0.5, rows - 0.5)]
    mid = math.atan2((rows - 1) / 2.0 - fr, (cols - 1) / 2.0 - fc)
    rel = [
        (math.atan2(r - fr, c - fc) - mid + math.pi) % (2 * math.pi) - math.pi for c, r in corners
    ]
    return mid + min(rel), mid + max(rel), False


def point_visibility(
    height: ArrayLike,
    light_col: float,
    light_row: float,
    light_z: float,
    bias_px: float = BIAS_PX,
) -> NDArray[np.float32]:
    """Visibility of each pixel from a point light at image position (col, row), height z.

    All three in pixel units, with the same zero as ``height``. The foot point may lie far
    outside the image (low dome lights) or inside it (lights near the zenith).
    """
    h = _as_height32(height)
    rows, cols = h.shape
    fc, fr, zl = float(light_col), float(light_row), float(light_z)
    if not all(math.isfinite(v) for v in (fc, fr, zl)):
        raise ValueError("point light position contains NaN or infinity")
    phi0, phi1, full = _angular_range(fc, fr, cols, rows)
    dx = np.array([-0.5, cols - 0.5]) - fc
    dy = np.array([-0.5, rows - 0.5]) - fr
    rho_max = float(np.max(np.hypot(dx[:, None], dy[None, :]))) + 1.0
    if full:
        rho_min = 0.0
    else:
        nc = min(max(fc, -0.5), cols - 0.5)
        nr = min(max(fr, -0.5), rows - 0.5)
        rho_min = float(max(0, math.floor(math.hypot(fc - nc, fr - nr)) - 1))
    n_phi = max(2, math.ceil((phi1 - phi0) * rho_max) + 1)
    n_rho = max(2, math.ceil(rho_max - rho_min) + 1)
    phi = np.linspace(phi0, phi1, n_phi)
    rho = rho_min + np.arange(n_rho, dtype=np.float64)
    rho32 = rho.astype(np.float32)[None, :]
    cos32 = np.cos(phi).astype(np.float32)[:, None]
    sin32 = np.sin(phi).astype(np.float32)[:, None]
    near = rho32 < 0.5  # (almost) under the light: the ray is vertical, nothing occludes
    lit = np.empty((n_phi, n_rho), np.float32)
    # Rays a block at a time: each ray (a row of the polar grid) is resampled and swept on its
    # own, so a block's rows come out exactly as from the whole grid, whose float32 planes at
    # 24 MP (about 10⁸ cells under a lamp at the dome's radius) had reached 4 GB.
    step = max(1, SWEEP_CELLS // n_rho)
    for a in range(0, n_phi, step):
        # Offsets from the foot point in float32 (sub-1e-3 px error), then shifted in place.
        map_c = cos32[a : a + step] * rho32
        map_c += np.float32(fc)
        map_r = sin32[a : a + step] * rho32
        map_r += np.float32(fr)
        hs = cv2.remap(h, map_c, map_r, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        inside = (map_c >= -0.5) & (map_c <= cols - 0.5) & (map_r >= -0.5)
        inside &= map_r <= rows - 0.5
        del map_c, map_r
        with np.errstate(divide="ignore", invalid="ignore"):
            sigma = (np.float32(zl) - hs) / rho32  # tangent of the depression angle
        occluder = np.where(inside & ~near, sigma, np.float32(np.inf))
        del hs, inside
        occ = np.empty_like(occluder)
        occ[:, 0] = np.inf
        np.minimum.accumulate(occluder[:, :-1], axis=1, out=occ[:, 1:])
        del occluder
        with np.errstate(divide="ignore", invalid="ignore"):
            rows_lit = sigma <= occ + np.float32(bias_px) / np.maximum(rho32, np.float32(0.5))
        lit[a : a + step] = rows_lit | near
        del sigma, occ, rows_lit
    # Back to the image.
    pc_ = (np.arange(cols, dtype=np.float64) - fc).astype(np.float32)[None, :]
    pr_ = (np.arange(rows, dtype=np.float64) - fr).astype(np.float32)[:, None]
    ang = np.arctan2(pr_, pc_)
    if full:
        ang = np.where(ang < phi0, ang + 2 * np.pi, ang)
    else:
        mid = 0.5 * (phi0 + phi1)
        ang = mid + (ang - mid + np.pi) % (2 * np.pi) - np.pi
    i_phi = ((ang - phi0) * ((n_phi - 1) / (phi1 - phi0))).astype(np.float32)
    i_rho = (np.hypot(pc_, pr_) - rho_min).astype(np.float32)
    vis = cv2.remap(lit, i_rho, i_phi, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    return np.clip(vis, 0.0, 1.0, out=vis)
