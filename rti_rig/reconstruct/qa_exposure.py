"""An image whose whole exposure is off: judged against the images lit from its elevation.

A flash that misfired at part power, an LED at half its output or a camera's auto-exposure
left on scale a whole image by a factor. The QA's other brightness checks compare the image
with a Lambertian fit of the session, which on a glossy object takes a halved or doubled image
in (the shipped simulated dome's coin, 1024 px, 12 lights: image_009 halved read 1.01 of the
fit on the pixels it explains) or is no rendering to judge it by. A leave-one-out fit of the
other images per pixel, linear in the light, does not take it in, but it predicts a glossy
object's images no better: correct images of the coin and of the industrial part read
0.1-8× that prediction (its highlights, its grazing lights).

What does predict an image's level on those objects is the images lit from the same elevation
(a dome's ring): their mean brightness over the frame agrees within 0.85-1.25× on every
correct simulated session measured (coin, painting, industrial part, tablet, relief; 256-1024
px, 12-48 lights; the simulated dome and the virtual arm, whose lights are at every elevation:
compared per unit of the light's height, 0.93-1.23 there), however glossy, since a highlight
covers few pixels of the frame. Where
they do not agree among themselves (a tilted object, lit from one side), nothing is judged.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: An image this many times brighter than the images lit from its elevation, or this many
#: times darker, has its exposure off (a stray flash, an LED at half power, auto-exposure):
#: correct images read 0.85-1.25× their mates, a halved or doubled one 0.50-0.63× or 1.7-2.1×
#: (the simulated sessions above).
EXPOSURE_OFF = 1.5
#: The images lit from within this many degrees of an image's light's elevation are its mates.
EXPOSURE_MATE_DEG = 5.0
#: ... judged only against at least this many mates (two that disagree cannot say which one
#: is right: a single mate is never enough) ...
EXPOSURE_MATES_MIN = 2
#: ... whose own mean levels agree within this factor (brightest over darkest): where the
#: object's brightness depends on the light's azimuth too (a tilted object), an elevation does
#: not predict it.
EXPOSURE_MATE_SPREAD = 1.5
#: Levels are compared per unit of the light's height above the object plane (its direction's
#: z); a light lower than this (about 3°) is not judged.
MIN_LZ = 0.05


def exposure_ratios(
    level: NDArray, lt: NDArray, usable: NDArray[np.bool_]
) -> tuple[NDArray, NDArray]:
    """Each image's mean ``level`` per unit of its light's height (``lz``) over the median of
    its mates' (per theirs) (the ``usable`` images
    lit from within :data:`EXPOSURE_MATE_DEG` of its light's elevation), and how many mates;
    NaN where fewer than :data:`EXPOSURE_MATES_MIN` mates, or mates that disagree by more than
    :data:`EXPOSURE_MATE_SPREAD` among themselves (pure).

    ``usable``: the images fit to stand as a mate (not found dark, wrong or black already:
    one misfire among three images of a ring must not make the other two look bright)."""
    n = len(level)
    ratio = np.full(n, np.nan)
    count = np.zeros(n, int)
    lz = np.clip(lt[:, 2], -1.0, 1.0)
    elevation = np.degrees(np.arcsin(lz))
    # per unit of the light's height: a surface facing the camera receives lz of it, and a
    # mate 5° higher near grazing is that much brighter (the virtual arm's tablet, 1024 px,
    # 24 lights: its 6° image read 0.65 of its 8° and 10° mates, 0.99-1.01 per lz)
    level = np.where(lz > MIN_LZ, level / np.maximum(lz, MIN_LZ), np.nan)
    ok = usable & np.isfinite(level) & (level > 0)
    for i in np.flatnonzero(np.isfinite(level) & (level > 0)):
        mates = ok & (np.abs(elevation - elevation[i]) <= EXPOSURE_MATE_DEG)
        mates[i] = False
        count[i] = int(mates.sum())
        if count[i] < EXPOSURE_MATES_MIN:
            continue
        m = level[mates]
        if m.max() > EXPOSURE_MATE_SPREAD * m.min():
            continue
        ratio[i] = float(level[i] / np.median(m))
    return ratio, count


def exposure_off(ratio: float) -> bool:
    """True when ``ratio`` (:func:`exposure_ratios`) is :data:`EXPOSURE_OFF` or more either way."""
    return bool(np.isfinite(ratio) and (ratio >= EXPOSURE_OFF or ratio <= 1.0 / EXPOSURE_OFF))
