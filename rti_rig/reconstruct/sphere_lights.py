"""Light directions from a reflective sphere's highlight (the highlight method of RTI).

Why: a dome's LED directions are what every fit and viewer reads from the ``.lp``; a new dome
has none until they are measured. The standard measurement (Cultural Heritage Imaging's
highlight method, RTIBuilder's and relight's sphere detection) puts a black glossy or chrome
sphere in frame: in each image the mirror highlight sits where the sphere's normal n is the
half-vector of the light l and the view v, so ``l = 2 (n·v) n − v``.

Conventions (docs/conventions.md): the camera is taken as orthographic, v = (0, 0, 1); the
frame has x to the image's right and y to its **top**, so image rows run against y. Circle and
highlight positions are in image pixels with pixel centres at integer coordinates (column 0 is
the first pixel's centre), as an image viewer and OpenCV report them.

Pure: arrays in, directions or a reason out. Nothing here reads a file or guesses a direction:
an image whose highlight cannot be measured is rejected with why, never given a direction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

#: A highlight whose blob reaches beyond this fraction of the radius is "on the rim": there the
#: normal changes fastest with position and the sphere's edge (and whatever lies behind it)
#: blends in, so a direction from it would be a guess.
RIM_FRACTION = 0.95
#: The blob is the pixels at least this fraction of the peak's height above the disc's median
#: (half maximum: the lobe's core, not its skirt).
BLOB_LEVEL = 0.5
#: The highlight's centre is the centroid of the region around the blob that stands at least
#: this fraction of the peak's height above the median, weighted by its height above that level.
#: Why lower than the blob's half maximum: a clipped highlight (the usual case at a real
#: exposure) is flat above half its height, its edge inside a pixel, so the half-maximum
#: centroid was off by up to 0.18 px (0.08 px median) on clipped Gaussian spots; with the skirt
#: below it, 0.08 px worst (0.02 px median).
CENTRE_LEVEL = 0.25
#: A peak must stand this many times the disc's median above it (and above the noise floor
#: below) to be a highlight; a disc with no clear peak has none (the LED did not light, or the
#: sphere is not where the circle says).
MIN_CONTRAST = 4.0
#: A blob of more than this fraction of the disc's area is too large to place: a saturated
#: smear (over-exposure, a diffuse or scratched sphere) whose centroid is not the peak.
MAX_BLOB_FRACTION = 0.02
#: A peak must also stand this fraction of the white level above the disc's median. Why: on a
#: dark frame (an LED that did not light) of a black sphere, an 8-bit JPEG is 0 but for a few
#: counts of noise: its median absolute deviation is 0, so the rules above took a pixel of 3
#: for a highlight and gave its direction. A sphere's highlight at any usable exposure stands
#: far above this (it is usually clipped).
MIN_HEIGHT_FRACTION = 0.025


class SphereCircleError(ValueError):
    """The sphere's circle does not fit the images (outside the frame, or too small)."""


@dataclass(frozen=True)
class Circle:
    """The sphere's outline in image pixels: centre column ``x``, centre row ``y``, radius."""

    x: float
    y: float
    radius: float


@dataclass(frozen=True)
class Highlight:
    """One image's highlight: its sub-pixel centre (column, row), its blob's area in pixels,
    and the light direction it gives (unit, frame of docs/conventions.md)."""

    column: float
    row: float
    area_px: int
    direction: tuple[float, float, float]


@dataclass(frozen=True)
class Rejected:
    """An image whose highlight gives no direction, and why, in words for the user."""

    reason: str


#: The smallest sphere radius measured: below it a pixel of highlight position is more than
#: 7° of light direction.
MIN_RADIUS_PX = 16.0


def check_circle(circle: Circle, shape: tuple[int, int]) -> None:
    """Refuse a circle that does not lie inside a ``(rows, cols)`` image or is too small."""
    rows, cols = shape
    if not all(math.isfinite(v) for v in (circle.x, circle.y, circle.radius)):
        raise SphereCircleError("the circle's centre and radius must be numbers")
    if circle.radius < MIN_RADIUS_PX:
        raise SphereCircleError(
            f"radius {circle.radius:g} px is too small to measure directions from (at least "
            f"{MIN_RADIUS_PX:g} px: shoot the sphere larger in frame)"
        )
    if (
        circle.x - circle.radius < -0.5
        or circle.y - circle.radius < -0.5
        or circle.x + circle.radius > cols - 0.5
        or circle.y + circle.radius > rows - 0.5
    ):
        raise SphereCircleError(
            f"the circle (centre {circle.x:g},{circle.y:g}, radius {circle.radius:g}) does not lie "
            f"inside the {cols}×{rows} px images: the whole sphere must be in frame"
        )


def direction_at(circle: Circle, column: float, row: float) -> tuple[float, float, float]:
    """The light direction whose mirror highlight is at (``column``, ``row``) on the sphere.

    n = ((column − x)/R, −(row − y)/R, √(1 − ρ²)) (rows run against y), v = (0, 0, 1), and
    l = 2 (n·v) n − v. Raises ValueError for a point outside the circle."""
    nx = (column - circle.x) / circle.radius
    ny = -(row - circle.y) / circle.radius
    rho2 = nx * nx + ny * ny
    if rho2 >= 1.0:
        raise ValueError(f"({column:g}, {row:g}) is outside the sphere's circle")
    nz = math.sqrt(1.0 - rho2)
    lx, ly, lz = 2 * nz * nx, 2 * nz * ny, 2 * nz * nz - 1.0
    norm = math.sqrt(lx * lx + ly * ly + lz * lz)
    return (lx / norm, ly / norm, lz / norm)


def find_highlight(
    grey: NDArray[np.floating], circle: Circle, white_level: float
) -> Highlight | Rejected:
    """The highlight of one linear grey image on the sphere in ``circle``.

    The blob is an 8-connected region of the disc that stands at least :data:`BLOB_LEVEL` of
    the peak's height above the disc's median; its centre is the centroid of the region around
    it at :data:`CENTRE_LEVEL`, weighted by the height above that level (sub-pixel, and a
    clipped plateau gives its middle).

    Only one such region, of more than one pixel, is a highlight: a lone pixel is a hot pixel
    or noise (a highlight seen through a lens spreads over several), and two regions are two
    lights or a reflection besides the LED's, either of which would give a direction that is
    not the LED's. ``white_level`` is the value of a clipped pixel: a peak must stand
    :data:`MIN_HEIGHT_FRACTION` of it above the median."""
    rows, cols = grey.shape
    check_circle(circle, (rows, cols))
    r0, r1 = (
        max(0, math.floor(circle.y - circle.radius)),
        min(rows, math.ceil(circle.y + circle.radius) + 1),
    )
    c0, c1 = (
        max(0, math.floor(circle.x - circle.radius)),
        min(cols, math.ceil(circle.x + circle.radius) + 1),
    )
    patch = np.asarray(grey[r0:r1, c0:c1], dtype=np.float64)
    yy, xx = np.mgrid[r0:r1, c0:c1].astype(np.float64)
    dist = np.hypot(xx - circle.x, yy - circle.y) / circle.radius
    disc = dist < 1.0
    values = np.where(disc, patch, -np.inf)
    peak = float(values.max())
    floor = float(np.median(patch[disc]))
    noise = float(np.median(np.abs(patch[disc] - floor))) * 1.4826
    least = max((MIN_CONTRAST - 1.0) * floor, 6 * noise, MIN_HEIGHT_FRACTION * white_level)
    if not math.isfinite(peak) or peak - floor <= least:
        return Rejected(
            f"no highlight on the sphere (brightest {peak:.0f} against a median of {floor:.0f}): "
            "did the LED light, and is the circle on the sphere?"
        )
    level = floor + BLOB_LEVEL * (peak - floor)
    above = (values >= level).astype(np.uint8)
    count, labels, stats, centres = cv2.connectedComponentsWithStats(above, connectivity=8)
    spots = [k for k in range(1, count) if stats[k, cv2.CC_STAT_AREA] > 1]
    if not spots:
        pr, pc = np.unravel_index(int(np.argmax(values)), values.shape)
        return Rejected(
            f"the brightest spot on the sphere is a single pixel (column {c0 + pc}, row "
            f"{r0 + pr}): a hot pixel or noise, not a highlight; did the LED light?"
        )
    if len(spots) > 1:
        at = " and ".join(
            f"column {c0 + centres[k][0]:.0f}, row {r0 + centres[k][1]:.0f}" for k in spots[:3]
        )
        return Rejected(
            f"{len(spots)} bright spots on the sphere ({at}): two LEDs lit, or a reflection "
            "besides the LED's; which one is the LED's cannot be told, so none is taken"
        )
    blob = labels == spots[0]
    area = int(blob.sum())
    if area > MAX_BLOB_FRACTION * math.pi * circle.radius**2:
        clipped = int((blob & (patch >= white_level)).sum())
        return Rejected(
            f"the highlight is a blob of {area} px ({clipped} of them clipped), more than "
            f"{MAX_BLOB_FRACTION:.0%} of the sphere: shoot with a shorter exposure, or use a "
            "glossier sphere"
        )
    if float(dist[blob].max()) > RIM_FRACTION:
        return Rejected(
            "the highlight is on the sphere's rim, where its position gives no reliable "
            "direction (a light near or below the sphere's equator, or a reflection of the "
            "ground): check the circle, or leave this LED to a later calibration"
        )
    # the centre from the skirt too: the region at CENTRE_LEVEL that holds the blob
    low = floor + CENTRE_LEVEL * (peak - floor)
    _, around = cv2.connectedComponents((values >= low).astype(np.uint8), connectivity=8)
    region = around == around[blob][0]
    weight = (np.minimum(patch, white_level) - low)[region]
    column = float((xx[region] * weight).sum() / weight.sum())
    row = float((yy[region] * weight).sum() / weight.sum())
    direction = direction_at(circle, column, row)
    if direction[2] <= 0.0:
        return Rejected(
            f"the highlight at column {column:.1f}, row {row:.1f} gives a light below the "
            "object plane: check the circle (centre and radius)"
        )
    return Highlight(column, row, area, direction)


def as_grey(image: NDArray[np.generic]) -> NDArray[np.float64]:
    """An image's mean over its colour channels (a grey image is returned as floats)."""
    arr = np.asarray(image)
    if arr.ndim == 3:
        return arr[..., :3].astype(np.float64).mean(axis=-1)
    return arr.astype(np.float64)


def angle_deg(a: tuple[float, float, float], b: tuple[float, float, float]) -> float:
    """The angle between two unit directions, in degrees."""
    dot = float(np.clip(np.dot(np.asarray(a), np.asarray(b)), -1.0, 1.0))
    return math.degrees(math.acos(dot))


#: The share of rays from the given centre that must cross one clear edge (the sphere's
#: outline) for the outline to count as found; fewer, and nothing is said of the circle.
OUTLINE_RAYS_FOUND = 0.8
#: An edge is clear where the step across it is at least this fraction of the image's range
#: (its 99th minus its 1st percentile): a black sphere on a lit ground steps by about all of it.
OUTLINE_MIN_STEP = 0.25
#: How far past the given circle, as a fraction of its radius, each ray looks for the outline.
OUTLINE_SEARCH = 0.3


def outline_circle(median: NDArray[np.floating], circle: Circle, rays: int = 120) -> Circle | None:
    """The sphere's outline as the images show it, searched near ``circle`` in ``median`` (the
    per-pixel median over the session's images: the highlights gone, the sphere's disc against
    its ground); None where no clear outline is found (a black sphere on black velvet, a
    chrome sphere mirroring a ground like itself).

    Why: a circle given a few pixels off (3 px at R = 48) had moved every LED by 7° (a pixel is
    about 115°/R), and the .lp was written without a word, though the sphere's outline stood
    in every image. Along each ray from the given centre the edge is the steepest step
    (sub-pixel, by the parabola through the step's peak); a circle is fitted to the edges by
    least squares (Kåsa's algebraic fit), after dropping rays whose edge lies off it (a stand,
    a shadow)."""
    img = np.asarray(median, dtype=np.float32)
    lo, hi = np.percentile(img, [1.0, 99.0])
    if not hi > lo:
        return None
    radii = np.arange(
        circle.radius * (1 - OUTLINE_SEARCH), circle.radius * (1 + OUTLINE_SEARCH), 0.25
    )
    angles = np.linspace(0.0, 2 * np.pi, rays, endpoint=False)
    xs = (circle.x + np.cos(angles)[:, None] * radii[None, :]).astype(np.float32)
    ys = (circle.y + np.sin(angles)[:, None] * radii[None, :]).astype(np.float32)
    profiles = cv2.remap(img, xs, ys, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    # the step across 2 px (8 samples of 0.25 px), so noise and antialiasing do not place it
    step = profiles[:, 8:] - profiles[:, :-8]
    peak = np.argmax(np.abs(step), axis=1)
    signed = step[np.arange(rays), peak]
    height = np.abs(signed)
    # the noise's own steps (their median absolute deviation as a sigma): a featureless
    # ground's steepest steps are noise, a few sigma high and of either sign
    sigma = 1.4826 * float(np.median(np.abs(step - np.median(step))))
    clear = (height >= OUTLINE_MIN_STEP * (hi - lo)) & (height >= 8.0 * sigma)
    # one outline: its step has one sign all round (a dark disc on a light ground, or not)
    polarity = np.sign(np.median(signed[clear])) if clear.any() else 0.0
    inner = (peak > 0) & (peak < step.shape[1] - 1)
    keep = clear & inner & (np.sign(signed) == polarity)
    if keep.sum() < OUTLINE_RAYS_FOUND * rays:
        return None
    idx = np.flatnonzero(keep)
    a = np.abs(step[idx, peak[idx] - 1])
    b = height[idx]
    c = np.abs(step[idx, peak[idx] + 1])
    denom = a - 2 * b + c
    shift = np.where(np.abs(denom) > 1e-12, 0.5 * (a - c) / np.where(denom == 0, 1, denom), 0.0)
    r = radii[0] + 0.25 * (peak[idx] + 4 + np.clip(shift, -0.5, 0.5))
    ex = circle.x + np.cos(angles[idx]) * r
    ey = circle.y + np.sin(angles[idx]) * r
    fitted = _kasa(ex, ey)
    for _ in range(2):  # rays whose edge is not the sphere's (a stand, a shadow) dropped
        off = np.abs(np.hypot(ex - fitted.x, ey - fitted.y) - fitted.radius)
        near = off <= max(1.0, 3.0 * float(np.median(off)))
        if near.sum() < OUTLINE_RAYS_FOUND * rays:
            return None
        ex, ey = ex[near], ey[near]
        fitted = _kasa(ex, ey)
    return fitted


def _kasa(x: NDArray[np.float64], y: NDArray[np.float64]) -> Circle:
    """The circle through points (x, y) in the least-squares sense of x² + y² + Dx + Ey + F."""
    design = np.column_stack([x, y, np.ones_like(x)])
    (d, e, f), *_ = np.linalg.lstsq(design, -(x * x + y * y), rcond=None)
    cx, cy = -d / 2, -e / 2
    return Circle(float(cx), float(cy), float(math.sqrt(max(cx * cx + cy * cy - f, 0.0))))
