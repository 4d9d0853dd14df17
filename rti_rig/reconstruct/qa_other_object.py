"""An image that is not a picture of the session's object: another acquisition's file.

Why: an acquisition assembled by hand (images copied from a card, a folder of another shoot
beside it) can hold one image of another object under a right name. Swapped into sessions of
the shipped simulated dome (one image of another scene in place of image_020 of 48), the
QA's other checks judged that picture by its level and light against the fit and named the
wrong cause ("misfired or dim light" mostly) or none: a painting's image in the relief's,
the flat plate's, the tablet's and the tilted plane's sessions was "good".

Every picture of one object shares its edges of relief and albedo whatever the light; another
object's does not. So an image whose edges, registered onto the median of the session's
(:func:`~rti_rig.reconstruct.qa_turn.edge_registration`: turn and shift allowed), correlate
below :data:`OTHER_OBJECT_SHARE` of the session's typical correlation is named, where the
session has edges to compare (typical at least :data:`MIN_TYPICAL`: a featureless plate has
none) and the image is lit as well as most (its mean level at least :data:`MIN_LEVEL_SHARE` of
the median image's: an image mostly in shadow, under a light behind a tilted plane, shares few
edges with the others).

Figures (``python -m benchmarks.qa_other_object``, through the CLI; and an earlier ad-hoc probe
of the reduced images from the JPEGs of the shipped simulated dome at 48 lights and virtual arm
at 24, every scene, image 20 swapped for each other scene's): a correct image's correlation is
at least 0.76 of its session's typical on every scene but the tilted plane, whose partly
shadowed images reach down to 0.38 (dome) and 0.43 (arm): the thinnest margin. Another scene's
picture, where lit enough to judge (28 of the 49 swaps into scenes with edges on the dome, 39
on the arm), sat at 0–0.31 of it, under the limit in 26 and 38: not the coin's session with
the relief's picture (0.72 and 0.67: two stamped reliefs alike) nor, on the dome, with the
tablet's (0.31). The flat plate has no edges to compare (typical 0.14–0.19): another picture
in its session is not told here.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rti_rig.reconstruct.qa_unchanging import FLAT_ADVICE

#: An image whose registered edges correlate below this share of the session's typical
#: correlation is not a picture of the object.
OTHER_OBJECT_SHARE = 0.3
#: The session's typical correlation below which there are too few edges to tell.
MIN_TYPICAL = 0.4
#: An image is judged only where its mean level is at least this share of the median image's.
MIN_LEVEL_SHARE = 0.5
#: Judged images needed for a typical correlation.
MIN_JUDGED = 6
#: Consecutive judged images named at once that are taken for a move, not stray files.
MIN_RUN = 3
#: The share of the judged images above which those named are taken for a move, not files.
MAX_SHARE = 0.1


def other_object_images(
    correlations: NDArray[np.float64], levels: NDArray[np.float64]
) -> dict[int, tuple[float, float]]:
    """``{index: (correlation, typical)}`` of the images whose edges are not the session's."""
    lit = np.isfinite(levels) & (levels >= MIN_LEVEL_SHARE * float(np.median(levels)))
    # an image not registered (ECC did not converge) shares nothing found: correlation 0;
    # a featureless one (nan) is not judged
    judged = lit & np.isfinite(correlations)
    if judged.sum() < MIN_JUDGED:
        return {}
    typical = float(np.median(correlations[judged]))
    if typical < MIN_TYPICAL:
        return {}
    found = judged & (correlations < OTHER_OBJECT_SHARE * typical)
    # a stray file is one image, or two: a run of MIN_RUN images in capture order (judged
    # ones; an unjudged image between does not break it), or more than MAX_SHARE of the
    # judged, is the object or camera moved past what registration follows (a 24 px shift
    # of a 512 px frame, a turn of 10°), which the move checks speak of, not a file
    if found.sum() > max(2, MAX_SHARE * judged.sum()):
        return {}
    order = np.flatnonzero(judged)
    flags = found[order]
    keep = flags.copy()
    start = 0
    for k in range(1, flags.size + 1):
        if k == flags.size or flags[k] != flags[start]:
            if flags[start] and k - start >= MIN_RUN:
                keep[start:k] = False
            start = k
    return {int(i): (float(correlations[i]), typical) for i in order[keep]}


#: The start of the problem :func:`other_object_problem` says.
OTHER_OBJECT = "not a picture of this object"


def other_object_problem(correlation: float, typical: float) -> str:
    """The image's problem, with its evidence and what to do (:data:`FLAT_ADVICE`, which a
    session that cannot reshoot has said in its own words)."""
    return (
        f"{OTHER_OBJECT}: its edges match the session's at {max(correlation, 0.0):.2f} where "
        f"its other images match at {typical:.2f} (another acquisition's file under this "
        f"name? put the right one back); {FLAT_ADVICE}"
    )
