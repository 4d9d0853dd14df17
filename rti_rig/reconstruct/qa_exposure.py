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

Two mates that agree are not enough on their own: on a real acquisition
(``tests/data/neuralrti_replay``) the object is about 3× brighter per unit of light height
lit from one side (azimuth -50..35°) than from the other, and its 59° image09 had its only
two mates, 104° and -149° of azimuth, both on the dark side and agreeing, so it was called
"about 3.6× too bright". An elevation predicts a level only where the session shows that the
azimuth does not matter: no two other images lit from one elevation disagree, and either two
images of another elevation agree, one lit from the image's side (within 45° of azimuth) and
one from a mate's, or the mates are at least 3 surrounding the sky (no gap of 180° in
azimuth). A ring of 3 (the simulated dome's 12-light coin) is judged by the other rings
agreeing; the real acquisition's 20° ring disagrees 1.9×, and nothing is judged there.
An uncalibrated dome's LEDs differ by ±20 %, and a correct image under a weak LED beside two
strong ones reads 1.7× darker than they: the emulated Nab dome's flat plate (24 lights,
``led_power_spread = 0.2``, seed 4) had its fault-free image_021 (0.60 of its 2 mates) called
"about 1.7× too dark". The limit widens by the scatter the session's own images show against
their mates (:func:`exposure_scatter`, the judged image left out): its limit is 1.73× there
(1.67-3.26× over seeds 0-9), and 1.5× is kept where the images agree (even LEDs).
Nor is "a highlight covers few pixels" true of a clipped image (image09 had 21 % clipped): the
QA judges no clipped image by this check, either way (it is named saturated instead).
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
#: The session shows that the azimuth does not matter between the image and its mates where two
#: other images lit from one elevation agree, one lit from within this many degrees of the
#: image's azimuth and the other of a mate's ...
EXPOSURE_AZIMUTH_DEG = 45.0
#: ... or where at least this many mates leave no gap of 180° or more between their azimuths.
EXPOSURE_SURROUND_MIN = 3
#: An image is named only this many times the robust RMS of ln ratio of the other images to
#: their mates (:func:`exposure_scatter`) from its mates' level, where that is beyond
#: :data:`EXPOSURE_OFF` (:func:`exposure_limit`): as far out as the QA's light scatter
#: explains a bright image on an uncalibrated dome (``LIGHT_SCATTER_Z``).
EXPOSURE_SCATTER_Z = 3.5
#: ... measured over at least this many other images with mates (fewer: the limit stays
#: :data:`EXPOSURE_OFF`).
EXPOSURE_SCATTER_MIN_IMAGES = 8
#: Levels are compared per unit of the light's height above the object plane (its direction's
#: z); a light lower than this (about 3°) is not judged.
MIN_LZ = 0.05


def exposure_ratios(
    level: NDArray, lt: NDArray, usable: NDArray[np.bool_]
) -> tuple[NDArray, NDArray]:
    """Each image's mean ``level`` per unit of its light's height (``lz``) over the median of
    its mates' (per theirs) (the ``usable`` images
    lit from within :data:`EXPOSURE_MATE_DEG` of its light's elevation), and how many mates;
    NaN where fewer than :data:`EXPOSURE_MATES_MIN` mates, where any two other usable images lit
    from one elevation (its mates among them) disagree by more than
    :data:`EXPOSURE_MATE_SPREAD`, or where no two other images of one elevation, lit from its
    side and a mate's (:data:`EXPOSURE_AZIMUTH_DEG`), agree and its mates do not surround it
    (:func:`_surround`) (pure).

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
    azimuth = np.degrees(np.arctan2(lt[:, 1], lt[:, 0]))
    # pairs of usable images lit from one elevation, and those whose levels disagree: the
    # session's own evidence on whether the azimuth matters (an object brighter lit from one
    # side, a tilted one, uneven LEDs)
    same_el = np.abs(elevation[:, None] - elevation[None, :]) <= EXPOSURE_MATE_DEG
    pair = same_el & ok[:, None] & ok[None, :] & ~np.eye(n, dtype=bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        apart = np.abs(np.log(level[:, None] / level[None, :])) > np.log(EXPOSURE_MATE_SPREAD)
    for i in np.flatnonzero(np.isfinite(level) & (level > 0)):
        mates = ok & same_el[i]
        mates[i] = False
        count[i] = int(mates.sum())
        if count[i] < EXPOSURE_MATES_MIN:
            continue
        others = pair.copy()
        others[i, :] = False
        others[:, i] = False
        if (others & apart).any():
            continue  # some elevation's images disagree (its own mates among them)
        near_i = _azimuth_apart(azimuth, azimuth[i]) <= EXPOSURE_AZIMUTH_DEG
        near_mate = np.zeros(n, bool)
        for m in np.flatnonzero(mates):
            near_mate |= _azimuth_apart(azimuth, azimuth[m]) <= EXPOSURE_AZIMUTH_DEG
        beyond_mates = others & ~(mates[:, None] & mates[None, :])
        evidence = beyond_mates & near_i[:, None] & near_mate[None, :]
        if not evidence.any() and not _surround(azimuth[mates]):
            continue  # nothing shows its side of the sky and its mates' lit alike
        ratio[i] = float(level[i] / np.median(level[mates]))
    return ratio, count


def exposure_scatter(level: NDArray, lt: NDArray, usable: NDArray[np.bool_]) -> NDArray:
    """For each image, the robust RMS (1.4826 × MAD) of ln(level per unit of height over the
    median of its mates') over the *other* ``usable`` images with at least
    :data:`EXPOSURE_MATES_MIN` mates, none of the agreement rules of :func:`exposure_ratios`
    applied; NaN where fewer than :data:`EXPOSURE_SCATTER_MIN_IMAGES` (pure).

    Why: how far a correct image's level strays from its mates' is what the session's own
    lights show (uneven LEDs, ±20 % on an uncalibrated dome); the judged image is left out so
    that its own fault does not widen the limit it is judged by."""
    n = len(level)
    lz = np.clip(lt[:, 2], -1.0, 1.0)
    elevation = np.degrees(np.arcsin(lz))
    per_z = np.where(lz > MIN_LZ, level / np.maximum(lz, MIN_LZ), np.nan)
    ok = usable & np.isfinite(per_z) & (per_z > 0)
    same_el = np.abs(elevation[:, None] - elevation[None, :]) <= EXPOSURE_MATE_DEG
    log_ratio = np.full(n, np.nan)
    for i in np.flatnonzero(ok):
        mates = ok & same_el[i]
        mates[i] = False
        if int(mates.sum()) >= EXPOSURE_MATES_MIN:
            log_ratio[i] = float(np.log(per_z[i] / np.median(per_z[mates])))
    scatter = np.full(n, np.nan)
    for i in range(n):
        others = np.isfinite(log_ratio)
        others[i] = False
        if int(others.sum()) >= EXPOSURE_SCATTER_MIN_IMAGES:
            x = log_ratio[others]
            scatter[i] = float(1.4826 * np.median(np.abs(x - np.median(x))))
    return scatter


def exposure_limit(scatter: float) -> float:
    """The factor either way from its mates' level from which an image's exposure is off:
    :data:`EXPOSURE_OFF`, or :data:`EXPOSURE_SCATTER_Z` times the session's ``scatter``
    (:func:`exposure_scatter`; NaN: not measured) where that is wider (pure)."""
    if not np.isfinite(scatter) or scatter <= 0.0:
        return EXPOSURE_OFF
    return float(max(EXPOSURE_OFF, np.exp(EXPOSURE_SCATTER_Z * scatter)))


def _azimuth_apart(azimuth_deg: NDArray, of_deg: float) -> NDArray:
    """Each azimuth's angle from ``of_deg`` around the circle (0-180°)."""
    d = np.mod(azimuth_deg - of_deg, 360.0)
    return np.minimum(d, 360.0 - d)


def _surround(azimuth_deg: NDArray) -> bool:
    """At least :data:`EXPOSURE_SURROUND_MIN` azimuths with no gap of 180° or more between
    them: mates on every side, whose agreement says the azimuth does not matter."""
    if len(azimuth_deg) < EXPOSURE_SURROUND_MIN:
        return False
    a = np.sort(np.mod(azimuth_deg, 360.0))
    gaps = np.diff(np.r_[a, a[0] + 360.0])
    return bool(gaps.max() < 180.0)


def exposure_off(ratio: float, limit: float = EXPOSURE_OFF) -> bool:
    """True when ``ratio`` (:func:`exposure_ratios`) is ``limit`` (:func:`exposure_limit`) or
    more either way."""
    return bool(np.isfinite(ratio) and (ratio >= limit or ratio <= 1.0 / limit))
