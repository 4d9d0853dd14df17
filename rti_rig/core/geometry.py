"""The coordinate frame shared by the whole project, and conversions within it.

Object-centred, right-handed: x to the right of the image, y to the top of the image (image rows
run the other way), z towards the camera. A light direction is the unit vector from the object to
the light. Azimuth is measured from +x towards +y; elevation from the object plane (0° grazing,
90° on the camera axis). This is the frame of `.lp` files, relight and DiLiGenT.

Conversions use ``atan2`` on both angles so that they stay accurate at the zenith (where the
azimuth is undefined and is reported as 0) and at the horizon (where ``asin(z)`` loses precision).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Below this horizontal length a direction is treated as the zenith (or nadir): azimuth 0.
ZENITH_EPS = 1e-12


def normalize(vectors: ArrayLike) -> NDArray[np.float64]:
    """Unit vectors along ``vectors`` (..., 3); raises on zero or non-finite input."""
    v = np.asarray(vectors, dtype=np.float64)
    if v.shape[-1] != 3:
        raise ValueError(f"expected vectors of length 3, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("direction contains NaN or infinity")
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    if np.any(n < 1e-12):
        raise ValueError("zero-length direction has no orientation")
    return v / n


def direction_from_az_el(azimuth_deg: ArrayLike, elevation_deg: ArrayLike) -> NDArray[np.float64]:
    """Unit direction(s) for azimuth and elevation in degrees; shape (..., 3)."""
    az = np.radians(np.asarray(azimuth_deg, dtype=np.float64))
    el = np.radians(np.asarray(elevation_deg, dtype=np.float64))
    az, el = np.broadcast_arrays(az, el)
    ce = np.cos(el)
    return np.stack([ce * np.cos(az), ce * np.sin(az), np.sin(el)], axis=-1)


def az_el_from_direction(
    direction: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Azimuth in [0, 360) and elevation in [-90, 90] degrees of direction(s) (..., 3).

    The input need not be unit length. At the zenith the azimuth is undefined; 0 is returned.
    """
    v = normalize(direction)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    h = np.hypot(x, y)
    el = np.degrees(np.arctan2(z, h))
    az = np.where(h < ZENITH_EPS, 0.0, np.degrees(np.arctan2(y, x)) % 360.0)
    # ``% 360`` can return 360.0 for tiny negative angles through rounding.
    az = np.where(az >= 360.0, 0.0, az)
    return az, el


def angle_between_deg(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Angle in degrees between direction(s) ``a`` and ``b``, accurate for tiny angles."""
    ua, ub = normalize(a), normalize(b)
    cross = np.linalg.norm(np.cross(ua, ub), axis=-1)
    dot = np.sum(ua * ub, axis=-1)
    return np.degrees(np.arctan2(cross, dot))


def pixel_to_frame_xy(rows: ArrayLike, cols: ArrayLike, height: int, width: int) -> NDArray:
    """Frame (x, y) of pixel centres, origin at the image centre, y up (rows run down)."""
    r = np.asarray(rows, dtype=np.float64)
    c = np.asarray(cols, dtype=np.float64)
    return np.stack([c - (width - 1) / 2.0, (height - 1) / 2.0 - r], axis=-1)


#: The elevation (degrees) of three lights whose directions are mutually orthogonal when they
#: stand 120° apart in azimuth: asin(1/√3), slant 54.74° from the camera's axis.
ORTHOGONAL_TRIAD_ELEVATION_DEG = float(np.degrees(np.arcsin(1.0 / np.sqrt(3.0))))


def even_layout(
    n: int, min_elevation_deg: float = 0.0, max_elevation_deg: float = 90.0
) -> NDArray[np.float64]:
    """The ideal directions of a homogeneous layout of ``n`` lights over an elevation band: the
    equal-area spiral (:func:`fibonacci_cap`), except for three lights, which stand 120° apart
    in azimuth at the elevation in the band nearest :data:`ORTHOGONAL_TRIAD_ELEVATION_DEG`.

    Why three apart: three lights are the fewest that determine a normal, and the spiral spreads
    them over the band's height, one of them near its floor (10°, 40° and 55° on the shipped
    dome), so any tilt away from the low light left two lit ("a 5° tilt leaves too few"), and
    the noise bound was about 40 % higher than it need be. Three mutually orthogonal lights
    minimise photometric stereo's noise for an unknown normal (Drbohlav & Chantler, ICCV 2005;
    algorithms notes §3: ``LᵀL = I``), and at 35° a normal tilted up to about 25° any way stays
    lit by all three. Measured (``python -m benchmarks.three_lights``; ``docs/planning.md``,
    "Three lights"): on the real 72-LED dome the mean normal error of three lights fell from
    16.9° to 9.9° (24 turns of each layout); on the simulator's painting, industrial part and
    tablet it fell by a third to three quarters in every draw, and the coin and a plane tilted
    50° (beyond any three lights) were ties."""
    if n == 3 and 0.0 <= min_elevation_deg <= max_elevation_deg <= 90.0:
        el = min(max(ORTHOGONAL_TRIAD_ELEVATION_DEG, min_elevation_deg), max_elevation_deg)
        return direction_from_az_el([0.0, 120.0, 240.0], el)
    return fibonacci_cap(n, min_elevation_deg, max_elevation_deg)


#: The largest condition number of three lights' directions under which a fit solves a pixel
#: lit by all three: ``rti_rig.reconstruct.solve.COND_LIMIT``, restated here (the core imports
#: nothing else of rti_rig; a test keeps the two equal).
TRIAD_RING_COND_LIMIT = 100.0


def triad_within_azimuths(
    min_azimuth_deg: float,
    max_azimuth_deg: float,
    min_elevation_deg: float,
    max_elevation_deg: float,
) -> NDArray[np.float64]:
    """Three light directions for an arm whose base turns only from ``min_azimuth_deg`` to
    ``max_azimuth_deg`` (degrees, in -180..180), within an elevation band: the triad of
    :func:`even_layout` (on its ring, at the elevation in the band nearest 35.26°), turned to
    the middle of the range where the range holds its 120° steps (240° of range or more), else
    on the same ring at the range's two limits and its middle.

    Why: the triad had been mapped linearly into the range, as the spiral of other counts is,
    which on an arm turning ±90° put its lights at -60°, 0° and 60°: 120° of the 180° the arm
    has, a noise bound ``tr (LᵀL)⁻¹`` of 19 against 4.5 at -90°/0°/90° (3 for the triad),
    and on the simulator's scenes, at ±90° and at ±60°, a larger normal error on four of five
    and a tie on the fifth, a plane tilted 50° that no three lights keep (``python -m
    benchmarks.three_lights``, its arm table; docs/planning.md). Spreading the lights further
    by raising some of them (the least noise bound with none below 35.26°: 3.97 at ±90°) was
    measured too and lost on the glossy coin and brushed steel, whose highlights the higher
    lights catch: the bound counts camera noise, not gloss, so the ring is kept. Under 34° of
    range (±17°) three lights on one ring determine no normal (condition number over
    :data:`TRIAD_RING_COND_LIMIT`, which the fit refuses), so there the middle light goes to the
    band's top (±15°: condition number 5.4 against 128)."""
    if max_azimuth_deg - min_azimuth_deg >= 360.0:
        return even_layout(3, min_elevation_deg, max_elevation_deg)
    el = min(max(ORTHOGONAL_TRIAD_ELEVATION_DEG, min_elevation_deg), max_elevation_deg)
    middle = 0.5 * (min_azimuth_deg + max_azimuth_deg)
    if max_azimuth_deg - min_azimuth_deg >= 240.0:
        return direction_from_az_el(middle + np.array([-120.0, 0.0, 120.0]), el)
    ring = direction_from_az_el([min_azimuth_deg, middle, max_azimuth_deg], el)
    if np.linalg.cond(ring) <= TRIAD_RING_COND_LIMIT:
        return ring
    # under 34° of range the ring determines no normal: its middle light to the band's top
    # (a band whose top is the ring's own leaves it as it is, and the plan says so)
    return direction_from_az_el(
        [min_azimuth_deg, middle, max_azimuth_deg], [el, max_elevation_deg, el]
    )


def fibonacci_cap(
    n: int, min_elevation_deg: float = 0.0, max_elevation_deg: float = 90.0
) -> NDArray[np.float64]:
    """``n`` directions spread evenly (equal solid angle) over an elevation band of the hemisphere.

    Heights are stratified uniformly in z (z is uniform on the sphere for equal areas) and
    azimuths advance by the golden angle, which gives near-uniform coverage for any ``n`` without
    the clustering of rings near the zenith.
    """
    if n <= 0:
        raise ValueError(f"need at least one direction, got {n}")
    if not 0.0 <= min_elevation_deg < max_elevation_deg <= 90.0:
        raise ValueError(
            f"elevation band [{min_elevation_deg}, {max_elevation_deg}] is not within [0, 90]"
        )
    z0, z1 = np.sin(np.radians([min_elevation_deg, max_elevation_deg]))
    i = np.arange(n)
    z = z0 + (z1 - z0) * (i + 0.5) / n
    az = i * np.pi * (3.0 - np.sqrt(5.0))
    r = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    return np.stack([r * np.cos(az), r * np.sin(az), z], axis=-1)
