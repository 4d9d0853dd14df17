"""A turn of the camera (or the object) about the view axis part-way through a session.

Why: the QA's drift checks measure *shifts*, on a crop where the object has lit structure
(:mod:`qa_drift`). A camera knocked so that it rolls about its axis moves the middle of the
frame by nothing and its corners by the most: the simulated dome's relief (512 px), its images
from image_020 on turned 3° about the centre (an imported folder), was called "good", and its
fitted normals were off by 1.7° at the 90th percentile against 0.19° as shot (0.67° at a 1°
turn). Nothing a fit says shows it either: every image is a believable picture of the object.

Measured here on the QA's reduced images (at most 256 px a side), on the edge strength of
their square roots as :func:`~rti_rig.reconstruct.qa_drift.edge_image` makes it (edges of
relief and albedo stay put whatever the light; shading edges do not, which is why the tilted
plane's images mostly go unjudged below; in linear levels a glossy coin's moving highlights
outweigh its relief). Each image's edge image is registered onto the median of up to
:data:`REFERENCE_IMAGES` of them by OpenCV's ECC with a Euclidean motion (rotation and shift:
a knock turns and shifts at once), whose angle is the image's turn; an image whose registered
edges correlate with the median below :data:`MIN_CORRELATION` is not judged (a grazing
light's shadows, a black frame). Two rounds: the images of the later side are turned back
before the median is made again, so a turn of most of the session does not leave the
reference a blend of both.

A turn is claimed as a step in capture order (the camera stays where the knock left it): the
split that leaves the least absolute deviation from each side's median angle, with at least
:data:`MIN_SIDE` judged images on each side, the medians differing by at least
:data:`TURN_MIN_DEG` and by :data:`TURN_Z` standard errors, :data:`SIDE_AGREE` of each side's
images nearer its own median, and neither side drifting along the capture order by
:data:`DRIFT_SHARE` of the step (a slow roll). Figures (``python -m benchmarks.qa_turn``):
still sessions of the shipped simulated dome and virtual arm over every scene, and the same
turned by 0.5°, 1° and 3° from two thirds of the way on.

Not seen here: a turn under :data:`TURN_MIN_DEG` (at 0.5° a 512 px frame's corners move
3 px, a 6000 × 4000 frame's 31 px), a single image turned and turned back (no step), and the
full size of a turn of an object whose edges are rings about the frame's centre (a sphere).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from rti_rig.reconstruct.qa_bands import median_of_images
from rti_rig.reconstruct.qa_drift import edge_image

#: An image whose edges, registered, correlate with the median's below this is not judged.
MIN_CORRELATION = 0.3
#: Judged images each side of a claimed turn, at least.
MIN_SIDE = 3
#: Edge images the median reference is made of, at most (spread over the capture order).
REFERENCE_IMAGES = 64
#: A side whose angles drift along the capture order by this share of the step is a slow
#: roll, not a step: no turn from one image is claimed.
DRIFT_SHARE = 0.5
#: The share of each side's images that must sit nearer their own side's median angle.
SIDE_AGREE = 0.75
#: The smallest turn claimed (degrees): still sessions' sides differ by up to 0.2° (an
#: ad-hoc probe of the shipped simulated dome and virtual arm, every scene, at 48 and 24
#: lights; benchmarks.qa_turn shows none claimed on them).
TURN_MIN_DEG = 0.5
#: ... and by at least this many standard errors of the two sides' medians.
TURN_Z = 8.0
#: The spread (degrees) below which no session's angles are taken to be: ECC on 256 px.
SPREAD_FLOOR_DEG = 0.03
#: ECC's stop: iterations and the change in its correlation below which it is done.
_ECC_CRITERIA = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-5)


@dataclass(frozen=True)
class Turn:
    """The images from ``first`` on (index) are turned by ``angle_deg`` (counter-clockwise
    in the image as seen, y up) against those before."""

    first: int
    angle_deg: float
    #: The first image judged turned, where images before it (from ``first``) were not
    #: judged (too few edges: a grazing light's shadow): the turn began between ``first - 1``
    #: and it, and the images between are taken as turned (the camera stays where a knock
    #: left it). None where ``first`` itself was judged.
    judged_first: int | None = None

    def corner_px(self, height: int, width: int) -> float:
        """How far the turn moved the frame's corners (pixels of an image of that size)."""
        return float(np.radians(abs(self.angle_deg)) * np.hypot(height, width) / 2)


def _turned(img: NDArray[np.float32], angle_deg: float) -> NDArray[np.float32]:
    h, w = img.shape
    m = cv2.getRotationMatrix2D((w / 2, h / 2), angle_deg, 1.0)
    return cv2.warpAffine(img, m, (w, h), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)


def _angle_onto(ref: NDArray[np.float32], edge: NDArray[np.float32]) -> float:
    """``edge``'s turn against ``ref`` in degrees (counter-clockwise as seen), or nan where
    ECC does not converge or the registered edges correlate below :data:`MIN_CORRELATION`."""
    warp = np.eye(2, 3, dtype=np.float32)
    try:
        cc, warp = cv2.findTransformECC(
            ref, edge, warp, cv2.MOTION_EUCLIDEAN, _ECC_CRITERIA, None, 5
        )
    except cv2.error:  # no convergence: no measurement
        return float("nan")
    if not cc >= MIN_CORRELATION:
        return float("nan")
    # the warp maps the reference's pixels onto the image's (rows run down): an image turned
    # counter-clockwise as seen reads a negative angle in those axes
    return -float(np.degrees(np.arctan2(warp[1, 0], warp[0, 0])))


def _edges(level: NDArray[np.float32]) -> NDArray[np.float32] | None:
    """The edge image of one reduced image's square root (None: featureless). Why the root:
    in linear levels a glossy coin's highlights, which move with the light, outweigh its
    relief, and its still images read turns of up to ±2.9° (the shipped dome's coin at 24
    lights); as roots, within ±0.9°."""
    return edge_image(np.sqrt(np.maximum(level, 0.0, dtype=np.float32)))


def image_angles(small: NDArray[np.float32], usable: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Each image's turn (degrees, counter-clockwise as seen; nan: not judged) against the
    median of the edge images; two rounds (module docstring). The median is of at most
    :data:`REFERENCE_IMAGES` of them, spread over the capture order, so that a dense
    acquisition's edge images are never all held at once (at 1000 lights, 260 MB)."""
    n = small.shape[0]
    angles = np.full(n, np.nan)
    have = [i for i in range(n) if usable[i]]
    if len(have) < 2 * MIN_SIDE:
        return angles
    spaced = np.linspace(0, len(have) - 1, min(len(have), REFERENCE_IMAGES)).round().astype(int)
    kept = {i: _edges(small[i]) for i in dict.fromkeys(have[k] for k in spaced)}
    turn: Turn | None = None
    for _ in range(2):
        placed = [
            e if turn is None or i < turn.first else _turned(e, -turn.angle_deg)
            for i, e in kept.items()
            if e is not None
        ]
        if len(placed) < 2 * MIN_SIDE:
            return angles
        ref = median_of_images(placed).astype(np.float32)
        for i in have:
            edge = kept[i] if i in kept else _edges(small[i])
            angles[i] = np.nan if edge is None else _angle_onto(ref, edge)
        # the second round's reference is of the session's earlier position (the later
        # side's edges turned back), so a turn of most of the session does not leave it a
        # blend of both; the angles are read as the images are
        turn = find_turn(angles)
        if turn is None:
            break
    return angles


def _spread(values: NDArray[np.float64]) -> float:
    return float(1.4826 * np.median(np.abs(values - np.median(values))))


def find_turn(angles: NDArray[np.float64]) -> Turn | None:
    """The step in capture order that :data:`TURN_MIN_DEG`, :data:`TURN_Z` and
    :data:`MIN_SIDE` admit, or None. The split is the one that leaves the least absolute
    deviation from each side's median (a median's difference alone hardly moves as the split
    slides into the later side: on a 1° turn from image 33 of 48 it chose image 26)."""
    judged = np.flatnonzero(np.isfinite(angles))
    a = angles[judged]
    best: tuple[float, int] | None = None
    for k in range(MIN_SIDE, a.size - MIN_SIDE + 1):
        left, right = a[:k], a[k:]
        cost = float(np.abs(left - np.median(left)).sum() + np.abs(right - np.median(right)).sum())
        if best is None or cost < best[0]:
            best = (cost, k)
    if best is None:
        return None
    k = best[1]
    left, right = a[:k], a[k:]
    step = float(np.median(right) - np.median(left))
    spread = max(
        _spread(np.concatenate([left - np.median(left), right - np.median(right)])),
        SPREAD_FLOOR_DEG,
    )
    # the standard error of a difference of two medians (1.2533: a median's of a normal
    # sample, against its mean's)
    z = abs(step) / (1.2533 * spread * np.sqrt(1 / left.size + 1 / right.size))
    if z < TURN_Z or abs(step) < TURN_MIN_DEG:
        return None
    # a step, not a slow roll: neither side's angles drift along the capture order by half
    # the step (a roll of 1° spread evenly over 100 images, 0.03° noise, had been claimed as
    # a 0.51° turn from image_051)
    for side, where in ((left, judged[:k]), (right, judged[k:])):
        slope = float(np.polyfit(where.astype(np.float64), side, 1)[0])
        if abs(slope) * float(where[-1] - where[0]) > DRIFT_SHARE * abs(step):
            return None
    # each side's images sit at its own angle, mostly: a later side of three whose median is
    # set by two images turned (or misread) is not a turn from the first of the three
    for side, other in ((left, right), (right, left)):
        own = np.abs(side - np.median(side)) < np.abs(side - np.median(other))
        if own.mean() < SIDE_AGREE:
            return None
    after = int(judged[k - 1]) + 1  # the image after the last judged unturned
    return Turn(
        first=after, angle_deg=step, judged_first=None if after == judged[k] else int(judged[k])
    )
