"""Whether an acquisition's images change with their light at all, judged on the QA's reduced
images.

Why: a session whose every image is the same picture (the dome's LEDs never fired while the
room light was on, or one frame saved under every light's name) was fitted and told
``QA verdict: good``. A PTM explains a constant image exactly (its constant term), so the
per-image checks, which compare each image with the fit, found nothing; the normal map was a
least-squares answer to lights that made no difference (24 identical frames at 46 % of full
scale read as a level surface of albedo 0.46).

A Lambertian surface under lights that do not all lie on one plane cannot look the same under
every one of them: its ``rho n . l`` changes from light to light. Only lights on one plane
(a ring at one elevation over a level object, where ``n . l`` is the same for every light) can
give identical images of a real object, so those are never judged here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: The images do not change with their light when their median pixel (lit in some image,
#: clipped in none) spreads less than this fraction of its brightest value between its brightest and
#: darkest image. Why 2 %: the reduced images are area averages, whose camera noise is well
#: below 1 % of a lit pixel; lights whose ``n . l`` for a single normal already differs by
#: :data:`MIN_LAMBERT_CHANGE` change a lit matte pixel by at least that fraction, and a real
#: session's median pixel (shadows, highlights) by tens of per cent.
UNCHANGING_SPREAD = 0.02
#: The judgement is made only when no surface normal can look the same under every light:
#: the relative RMS misfit of the best ``L x = 1`` (a constant rendering ``n . l``) is at least
#: this. Lights on one plane (a ring at one elevation) read 0; 4 to 1000 lights spread over 10-90°
#: elevation read 0.33-0.38.
MIN_LAMBERT_CHANGE = 0.1
#: The words of the problem, said once for the run of images (``QAReport.verdict``).
UNCHANGING = "the images do not change with their light"


def lambert_change(lights: NDArray[np.floating]) -> float:
    """How far the best constant Lambertian rendering falls from constant over ``lights``
    (N×3): the relative RMS residual of ``L x = 1`` in least squares (0: lights on one plane,
    where some normal sees every light alike)."""
    lt = np.asarray(lights, dtype=np.float64).reshape(-1, 3)
    ones = np.ones(len(lt))
    x, *_ = np.linalg.lstsq(lt, ones, rcond=None)
    return float(np.sqrt(np.mean((lt @ x - ones) ** 2)))


def unchanging_spread(
    small: NDArray[np.floating],
    small_sat: NDArray[np.bool_],
    dark: float,
    lights: NDArray[np.floating],
) -> float | None:
    """The median relative spread of ``small``'s (N, h, w) lit pixels clipped in no image when
    it is below :data:`UNCHANGING_SPREAD` on lights that cannot give identical images (the
    images do not change with their light), else None.

    ``small_sat`` marks clipped reduced pixels and ``dark`` is the QA's dark level, in the
    units of ``small``. Fewer than 3 images, lights on one plane, or no lit unclipped pixel:
    None (nothing to judge)."""
    n = small.shape[0]
    if n < 3 or lambert_change(lights) < MIN_LAMBERT_CHANGE:
        return None
    # the extremes of the images as they are, then in float64: the same values as of a
    # float64 copy of the stack (a maximum is one of its inputs), without that copy (twice
    # the reduced images' memory, at 1000 lights of 256 px 520 MB)
    stack = small.reshape(n, -1)
    hi = stack.max(axis=0).astype(np.float64)
    # lit in some image (a pixel shadowed in others spreads fully: it changed) and clipped in
    # none (a clipped pixel reads full scale whatever its light)
    usable = (hi > dark) & ~small_sat.reshape(n, -1).any(axis=0)
    if not usable.any():
        return None
    lo = stack.min(axis=0).astype(np.float64)
    spread = float(np.median((hi[usable] - lo[usable]) / hi[usable]))
    return spread if spread < UNCHANGING_SPREAD else None


#: What :func:`unchanging_problem` tells a session that can reshoot to do (replaced where it
#: cannot: :data:`rti_rig.reconstruct.qa.REDO_ADVICE`).
UNCHANGING_ADVICE = "check that each light fires, then reshoot"
#: What :func:`flat_problem` tells a session that can reshoot to do (likewise replaced).
FLAT_ADVICE = "reshoot it"


def unchanging_problem(spread: float) -> str:
    """What the verdict says of every image of an acquisition that does not change with its
    light, and what to do."""
    return (
        f"{UNCHANGING} (their median pixel varies {spread:.1%} from image to image, where "
        "these lights would change any surface's shading): the lights never changed (the "
        "dome's LEDs did not fire while another light was on, or one frame was saved under "
        f"every name); {UNCHANGING_ADVICE}"
    )


#: The words of one image that shows no picture of the object (:func:`flat_images`).
FLAT_FRAME = "a flat frame: no picture of the object"
#: An image is judged flat against the others only where their median spread is at least this
#: many times :data:`UNCHANGING_SPREAD`: an object whose every image is nearly flat (a
#: featureless card under distant lights) gives no image that differs from the rest.
FLAT_AGAINST = 5.0
#: The fewest lit, unclipped reduced pixels a flat image is judged on.
FLAT_MIN_PIXELS = 16
#: The images an image's spread is judged against: those of its nearest lights by angle. Why
#: not every image: a light near the camera axis shades a gently sloped matte object (a sheet
#: of paper, a plaster cast) by the cosine of its slope, under 2 % across the frame at slopes
#: of 1-1.5°, while raking lights shade it by tens of per cent (16-bit images of such a sheet
#: under the real replay's lights: its two highest lights, 80-82°, read 1.2-1.7 % against a
#: median 11 % and were called flat). Lights near it shade it alike; a frame from another
#: source differs from them.
FLAT_NEIGHBOURS = 4


def flat_images(
    small: NDArray[np.floating],
    small_sat: NDArray[np.bool_],
    dark: float,
    lights: NDArray[np.floating],
) -> dict[int, tuple[float, float]]:
    """The images of ``small`` (N, h, w; ``small_sat`` and ``dark`` as in
    :func:`unchanging_spread`) that are one level across the frame while the images of their
    :data:`FLAT_NEIGHBOURS` nearest ``lights`` (N×3) are not: each with its spread and those
    images' median spread.

    Why: one flat grey frame among lit ones (a frame from another source, a lens covered, a
    camera that sent a blank buffer) was judged "good" at a level near its mates', and "too
    bright for its light" above it: the per-image checks compare it with a fit that, at its
    level, it matches on average. An image of the object under a light shades and shadows it;
    a frame of one level has nothing of the object in it. The spread is the 10th to 90th
    percentile of the pixels lit in some image and clipped in none, over the 90th; an image
    whose 90th percentile is dark is a misfire, judged elsewhere.
    """
    n = small.shape[0]
    if n < 3:
        return {}
    # the images as they are, one row at a time in float64: a float64 copy of the stack and
    # the percentile's copy of it had held the reduced images three times over
    stack = small.reshape(n, -1)
    usable = (stack.max(axis=0) > dark) & ~small_sat.reshape(n, -1).any(axis=0)
    if int(usable.sum()) < FLAT_MIN_PIXELS:
        return {}
    lo, hi = np.array(
        [np.percentile(row[usable].astype(np.float64), [10.0, 90.0]) for row in stack]
    ).T
    spread = np.where(hi > dark, (hi - lo) / np.where(hi > 0.0, hi, 1.0), np.nan)
    lt = np.asarray(lights, dtype=np.float64).reshape(n, 3)
    lt = lt / np.maximum(np.linalg.norm(lt, axis=1, keepdims=True), 1e-12)
    found: dict[int, tuple[float, float]] = {}
    for i in np.flatnonzero(spread < UNCHANGING_SPREAD):
        near = np.argsort(-(lt @ lt[i]), kind="stable")
        near = near[near != i][:FLAT_NEIGHBOURS]
        others = spread[near]
        others = others[np.isfinite(others)]
        typical = float(np.median(others)) if others.size >= 2 else 0.0
        if typical >= FLAT_AGAINST * UNCHANGING_SPREAD:
            found[int(i)] = (float(spread[i]), typical)
    return found


def flat_problem(spread: float, typical: float) -> str:
    """What the verdict says of a flat image (:func:`flat_images`), and what to do."""
    return (
        f"{FLAT_FRAME} (one level across the frame: it varies {spread:.1%} across it, where "
        f"the images of the nearest lights vary a median {typical:.0%}); a frame from "
        f"another source, a covered lens or a camera fault; {FLAT_ADVICE}"
    )
