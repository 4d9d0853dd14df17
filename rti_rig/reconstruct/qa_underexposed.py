"""A session under-exposed throughout: every image far darker than the camera's range allows.

One exposure serves a whole session, so an exposure left far too short (a setting carried over
from a brighter set-up, a lens stopped down, a weaker dome) darkens every image alike. The
QA's other brightness checks compare an image with the others or with a fit of them, and
find nothing: the images agree. The verdict had said "good" of a simulated dome session shot
at 1/50 of its exposure (``camera.exposure_s = 0.001``, 24 lights): its brightest pixels
reached 1.3 % of full scale, its expected normal error was 7× the correctly exposed
session's (0.99° against 0.13°) and its JPEGs, which relight and RTIBuilder read, used 30 of
their 256 levels. At 1/500 the frames are black (``signal_check``), which was already named.

Judged by the brightest image's brightest pixels (:data:`~rti_rig.reconstruct.qa
.PEAK_PERCENTILE` of the reduced frame), which a correctly exposed session puts well up the
camera's range: 0.067-1.0 on the shipped simulated dome and arms over every scene, with all
their lights and with those up to 15° only (the least, a matte plate lit from the dome's 10°
ring alone; next, 0.096: ``python -m benchmarks.qa_underexposed``, docs/reconstruction.md),
and 1.0 in the real acquisition of ``tests/data/neuralrti_replay`` (its qa.json). Not called:
the dome's relief at 1/10 of its exposure (0.055). Only where a full scale is known (integer
frames): float frames have none, and nothing is claimed there.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

#: The words that open the problem, said once for the run of images (:attr:`QAReport.verdict`).
UNDEREXPOSED = "under-exposed throughout"
#: What an under-exposed session that can reshoot is told to do (replaced where a session
#: cannot follow it: :data:`~rti_rig.reconstruct.qa.REDO_ADVICE`).
MORE_EXPOSURE = "reshoot with more exposure"
#: A session whose brightest image's brightest pixels reach less than this share of full scale
#: is under-exposed: 4 stops below :data:`AIM_PEAK`. The dimmest correct session measured (a
#: matte plate lit only from the simulated dome's 10° ring) reaches 0.067, 2.1× above it; the
#: 1/50-exposure one 0.011.
UNDEREXPOSED_PEAK = 1.0 / 32.0
#: ... and none of whose images has this many pixels of the frame reduced by area (to about
#: 256 px a side, 65 536 pixels: 0.024 % of it) at or above it: a small object on a black
#: ground, under 0.1 % of the frame, correctly exposed, had its frame's 99.9th percentile in
#: the background and was called 6 stops under (a sphere of radius 8 px in 512² frames).
UNDEREXPOSED_MIN_PIXELS = 16
#: The level the advice's factor aims the brightest pixels at: half of full scale, with room
#: for the highlights of lights that were dimmer in the session measured.
AIM_PEAK = 0.5


def underexposed_problem(peak: NDArray, well_lit: NDArray | None = None) -> str | None:
    """The problem every image of a session under-exposed throughout carries, or None.

    ``peak``: each image's brightest level as a share of full scale (NaN where there is no
    full scale: float frames); ``well_lit``: how many pixels of each reduced image reach
    :data:`UNDEREXPOSED_PEAK`. None where any image's level is unknown, the brightest reaches
    :data:`UNDEREXPOSED_PEAK`, or any image has :data:`UNDEREXPOSED_MIN_PIXELS` pixels that
    do (pure)."""
    values = np.asarray(peak, dtype=float)
    if values.size == 0 or not np.isfinite(values).all():
        return None
    if well_lit is not None and np.any(np.asarray(well_lit) >= UNDEREXPOSED_MIN_PIXELS):
        return None
    top = float(values.max())
    if top >= UNDEREXPOSED_PEAK:
        return None
    if top <= 0.0:
        return None  # black: said as such by the black-throughout check
    factor = AIM_PEAK / top
    stops = math.log2(factor)
    return (
        f"{UNDEREXPOSED}: the brightest pixels of the brightest image reach {top:.1%} of full "
        f"scale (a correct exposure puts them near half of it or more), about {stops:.1f} "
        f"stops under: every image is noisier than this object allows, and 8-bit copies of "
        f"them use few of their levels; about {_factor(factor)}× the exposure brings them to "
        f"{AIM_PEAK:.0%}; {MORE_EXPOSURE}"
    )


def _factor(factor: float) -> str:
    """``factor`` to two significant figures: what a user sets an exposure to."""
    return f"{factor:.2g}" if factor < 100 else f"{factor:.0f}"
