"""Can an image's light direction be judged at all? Measured per image, not from the errors.

The QA finds, per image, the vector ``s`` explaining it best as ``b . s`` (``b = rho n`` of the
reference fit) and compares its direction with the recorded light. That comparison means
something only if the image *is* close to some Lambertian rendering of the fit: on a glossy,
saturated or interreflecting surface (the real dome acquisition in tests/data, the emulated
domes' 48-px coin) the best direction lands tens of degrees from any light whatever was
recorded. The previous gate inferred this from the median error over the images, and so switched
itself off when many lights were swapped (6 or 9 pairs of 36): the fault it looks for.

Here the test uses no recorded light: :func:`relative_misfit` is the image's distance from its
best rendering. A wrong light is just another direction, so its misfit stays small.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: An image further than this from its best Lambertian rendering (median |residual| over the
#: median rendered value) has no measurable light direction.
MISFIT_LIMIT = 0.1


def relative_misfit(b: NDArray, img: NDArray, s: NDArray, lit: NDArray[np.bool_]) -> float:
    """Median ``|img - b . s|`` over the median of ``b . s`` on the pixels ``lit`` by the best
    vector ``s`` (no recorded light enters): large on a glossy, saturated or interreflecting
    surface, small for a wrong light (just another direction)."""
    if lit.sum() < 10:
        return float("inf")
    pred = b[lit] @ s
    scale = float(np.median(np.abs(pred)))
    if scale <= 0:
        return float("inf")
    return float(np.median(np.abs(img[lit] - pred)) / scale)
