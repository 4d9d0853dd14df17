"""How surely the QA's fit places the object's mean surface, and a black frame at a faint light.

A light's image is judged against what the fit's normals predict under it. Two places where
that prediction says little, measured on emulated domes (docs/reconstruction.md, "QA verdict"):

* **The fit's surface is uncertain under uneven lights.** Photometric stereo assumes the
  lights equally strong; an uncalibrated dome's LEDs are not (``light_scatter``), and the fit
  tilts every normal by its lights' errors. The emulated minirti dome's tilted plane (50°,
  12 lights, ``led_power_spread = 0.2``, seed 5) was fitted at a 40-44° tilt: its image_006,
  whose light lies 5.7° *below* the true plane, sat 0.9-1.7° above the fitted one, reached
  16-33 pixels at n · l > 0.2 there, and its dark image was told "misfired, no light" in a
  fault-free session. :func:`surface_margin_deg` is how far above the fitted mean surface a
  light must lie for its dark image to be evidence: twice the standard deviation of that
  surface's normal under gains scattered as measured (first-order error propagation of
  least-squares photometric stereo, one mean pixel lit by the lights above it). 6.3° there.
* **A light that reaches the object at a small n · l** (below 0.2 everywhere: a flat plate's
  lights below 11.5°) has no gain judged: its ratio to the prediction is noisy and, on a
  relief, shadowed. A black frame is still told from a lit one wherever the prediction stands
  above the session's dark level (:func:`faint_black_frame`): a flat matte plate's 3.2° light
  reads 0.75 of the prediction there, the same light dead 0.004.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: A dark image is judged only on a light more than this many standard deviations of the
#: fitted mean surface's normal above that surface (:func:`surface_margin_deg`). Two, for a
#: one-sided tail of about 2.3 %: calling the dark image of a working LED below the real surface
#: a misfire tells a user to repair it, while a wider margin leaves more dead low LEDs unjudged.
#: The deviation is measured from the scatter left after the fit, which the fit has partly
#: absorbed: on strongly uneven domes the margin is smaller than the real tilt
#: (docs/reconstruction.md, the margin's measured cost).
SURFACE_MARGIN_SD = 2.0
#: Below this many lights above the mean surface the fit's surface has no spread to measure.
SURFACE_MIN_LIGHTS = 3


def surface_margin_deg(lt: NDArray, mean_n: NDArray, light_scatter: float) -> float:
    """Degrees above the fitted mean surface within which a dark image is no evidence.

    Why: a light gain ``1 + e_i`` (``e`` of RMS ``light_scatter``) turns least-squares
    photometric stereo's solution ``b = A^+ I`` by ``A^+ diag(e) A b``; the spread of ``b``
    across the mean surface's normal is how far the fit can have tilted that surface. 0 where
    the scatter was not measured (NaN: too few renderings) or the mean normal is unknown;
    equal LEDs (scatter 0.000-0.002 on the emulated domes) leave the rule as it was.
    """
    norm = float(np.linalg.norm(mean_n))
    if not np.isfinite(light_scatter) or light_scatter <= 0.0 or norm == 0.0:
        return 0.0
    m = np.asarray(mean_n, dtype=np.float64) / norm
    dirs = np.asarray(lt, dtype=np.float64)
    dirs = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
    shade = dirs @ m
    above = shade > 0.0
    if int(above.sum()) < SURFACE_MIN_LIGHTS:
        return 0.0
    a = dirs[above]
    pinv = np.linalg.pinv(a)  # 3 x k
    cov = light_scatter**2 * (pinv * shade[above] ** 2) @ pinv.T
    across = np.eye(3) - np.outer(m, m)
    sd = float(np.sqrt(max(np.trace(across @ cov @ across), 0.0)))
    return float(SURFACE_MARGIN_SD * np.degrees(np.arctan(sd)))


def faint_black_frame(
    img: NDArray, pred: NDArray, usable: NDArray, dark: float, min_pixels: int, percentile: float
) -> tuple[float, float]:
    """(median, bright end: the ``percentile``) of image / prediction where the prediction
    stands above the dark level ``dark``; NaNs where fewer than ``min_pixels`` are ``usable``.

    Why: a light that fired lifts each such pixel above the dark level by the prediction, so
    a frame at the dark level there is one no light reached, whatever n · l; a dimmer one is
    not judged here (a faint image's level is the prediction's weakest and, on a relief,
    shadowed part)."""
    use = usable & (pred > dark)
    if int(use.sum()) < min_pixels:
        return float("nan"), float("nan")
    ratio = img[use] / pred[use]
    return float(np.median(ratio)), float(np.percentile(ratio, percentile))
