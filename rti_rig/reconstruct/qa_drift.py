"""Registration drift between the images of one acquisition, measured without the fit.

Used where it is trustworthy: :func:`edge_shifts_trusted` says whether the images of a session
hold their edges still (an object with albedo texture, like the real acquisition in tests/data:
clean shifts within 0.6 px) or not (a pure relief, whose shading edges move with the light by
up to 2 px; a glossy 48-px coin). Where it is not, the QA's drift against the fit's prediction
is the only measure.

The QA used to measure each image's shift against the fit's prediction. That reference is
corrupted by the very fault it looks for: when the object moves part-way through a session the
fit blends two positions, and a (3, 2) px move from image 21 of 36 was found on image 21 only.
Shading is not a usable reference either (a grazing light's unmodelled shadows moved the peak
by about a pixel).

Here each image is reduced to its **edge strength** (gradient magnitude of the lightly blurred
image, scaled by its own 99th percentile): edges of the relief and the albedo sit in the same
place whatever the light, with a sign and strength that vary, which the magnitude and the scaling
remove. The reference is the per-pixel **median** of those edge images, so it stays where most
images are; each image's shift against it is found by phase correlation (OpenCV, sub-pixel), the
images are moved back and the median recomputed (a few rounds), so a block of moved images does
not drag the reference. An image is judged only when its edge image correlates with the reference
(the peak's response): a black frame or a featureless image has no position to measure.
"""

from __future__ import annotations

import cv2
import numpy as np
from numpy.typing import NDArray

#: Blur (sigma, pixels) before the gradient: noise out, edges kept.
EDGE_BLUR = 1.5
#: A phase-correlation peak below this response is no measurement (no common structure).
MIN_RESPONSE = 0.03
#: Rounds of (median reference, shifts, move back).
ROUNDS = 3


def edge_image(img: NDArray[np.float32]) -> NDArray[np.float32] | None:
    """Gradient magnitude scaled by its 99th percentile, or None for a featureless image."""
    g = cv2.GaussianBlur(img.astype(np.float32), (0, 0), EDGE_BLUR)
    gx = cv2.Sobel(g, cv2.CV_32F, 1, 0)
    gy = cv2.Sobel(g, cv2.CV_32F, 0, 1)
    m = np.hypot(gx, gy)
    scale = float(np.percentile(m, 99.0))
    if not np.isfinite(scale) or scale <= 0:
        return None
    return np.minimum(m / scale, 2.0)


def _move(img: NDArray, dx: float, dy: float) -> NDArray:
    m = np.float32([[1, 0, dx], [0, 1, dy]])
    return cv2.warpAffine(
        img, m, (img.shape[1], img.shape[0]), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT
    )


def measure_drift(
    crops: NDArray[np.float32], usable: NDArray[np.bool_]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per image ``(dx, dy)`` (image axes, x right, y down) against the session's median edge
    image, and the correlation response. ``usable`` False (a dark or misfired frame) or a
    featureless image gives NaN: not measured."""
    n = crops.shape[0]
    edges = [edge_image(c) if usable[i] else None for i, c in enumerate(crops)]
    shifts = np.zeros((n, 2))
    response = np.zeros(n)
    have = [i for i in range(n) if edges[i] is not None]
    if len(have) < 3:
        return np.full((n, 2), np.nan), response
    window = cv2.createHanningWindow((crops.shape[2], crops.shape[1]), cv2.CV_64F)
    for _ in range(ROUNDS):
        back = [_move(edges[i], -shifts[i, 0], -shifts[i, 1]) for i in have]
        ref = np.median(np.stack(back), axis=0).astype(np.float64)
        for i in have:
            (dx, dy), r = cv2.phaseCorrelate(ref, edges[i].astype(np.float64), window)
            shifts[i] = (dx, dy)
            response[i] = r
    out = np.full((n, 2), np.nan)
    for i in have:
        if response[i] >= MIN_RESPONSE:
            out[i] = shifts[i]
    return out, response


#: The edge shifts are trusted when their robust spread about the session's median is at
#: most this (pixels).
TRUSTED_SPREAD_PX = 0.35


def edge_shifts_trusted(shifts: NDArray[np.float64]) -> tuple[bool, NDArray[np.float64]]:
    """Are the edge shifts a measurement on this object (robust spread about their median at
    most :data:`TRUSTED_SPREAD_PX`)? Returns that and each image's shift from the median
    (NaN where not measured). A block of moved images is a minority or the majority: either
    way the median sits on one block and the spread on that block's noise."""
    ok = np.isfinite(shifts[:, 0])
    dev = np.full_like(shifts, np.nan)
    if ok.sum() < 5:
        return False, dev
    centre = np.median(shifts[ok], axis=0)
    for _ in range(3):  # the centre of the largest block, not between two blocks
        near = ok & (np.hypot(*(shifts - centre).T) <= 1.0)
        if near.sum() < max(3, ok.sum() // 2):
            break
        centre = np.median(shifts[near], axis=0)
    dev[ok] = shifts[ok] - centre
    dist = np.hypot(dev[ok, 0], dev[ok, 1])
    still = dist[dist <= 1.0]
    if still.size < max(3, (ok.sum() + 1) // 2):
        return False, dev
    spread = 1.4826 * float(np.median(still))
    return spread <= TRUSTED_SPREAD_PX, dev


def move_back(img: NDArray, dx: float, dy: float) -> NDArray:
    """The image moved back by its measured shift (edges reflected)."""
    return _move(img, -dx, -dy)
