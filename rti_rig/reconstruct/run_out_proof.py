"""End-of-run proof that a camera-triggered dome's order held, without any reflectance model.

The cceh/rti firmware (``firmware/rti.cpp``) stops programming new LEDs once its order is
exhausted: every flash after its last LED re-lights that LED. So, after image *n* (= the
firmware's last LED *n*), one more **proof frame** is shot:

* without a slip the proof frame is lit by LED *n* again: it equals image *n* up to noise, and
  image *n*−1 (LED *n*−1) differs from image *n*;
* after a double step anywhere in the run that the per-image check did not see, the dome reached
  LED *n* one image early: images *n*−1, *n* and the proof frame are all lit by LED *n*, so
  image *n*−1 is as alike to image *n* as the proof frame is.

The pair (image *n*, proof frame) is the same LED twice: it calibrates what "same LED" looks
like on this object at this noise level, with no model of the object. The decision compares
plain image differences (:func:`relative_difference`) on the reduced grey images of the slip
check. It proves nothing when LEDs *n*−1 and *n* light the object alike (then it says
"cannot verify", never "ok"), and nothing when the order stops before the firmware's last LED
(the dome has not run out; no frame shows the same LED twice).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: Image *n*−1 must differ from image *n* by more than this many times the proof frame does…
SAME_RATIO = 3.0
#: …and by more than this relative RMS difference (flash-to-flash repeatability of an LED and
#: the noise of the reduced image stay well below it; neighbouring LEDs of the shipped order
#: differ by 0.06–0.77, median over a run, on the simulator's scenes).
MIN_DIFFERENCE = 0.02
PROVED, DOUBLE, CANNOT = "proved", "double-step", "cannot-verify"


def relative_difference(a: NDArray[np.floating], b: NDArray[np.floating]) -> float:
    """RMS of ``a - b`` over the RMS of their mean image (0: identical; scale-free)."""
    a64, b64 = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    scale = float(np.sqrt(np.mean(((a64 + b64) / 2.0) ** 2)))
    return float(np.sqrt(np.mean((a64 - b64) ** 2)) / max(scale, 1e-12))


@dataclass(frozen=True)
class RunOutProof:
    """The decision on the last two images of the order and the proof frame."""

    kind: str
    reason: str
    #: d(image n, proof frame): the same LED twice, if the order held.
    same: float
    #: d(image n-1, image n): two neighbouring LEDs, if the order held.
    neighbours: float
    #: median d of consecutive images earlier in the run (how this object shows neighbours).
    typical: float

    @property
    def proved(self) -> bool:
        return self.kind == PROVED

    def to_json(self) -> dict[str, object]:
        return {
            "kind": self.kind,
            "reason": self.reason,
            "d_last_proof": self.same,
            "d_before_last_last": self.neighbours,
            "d_consecutive_median": self.typical,
            "same_ratio": SAME_RATIO,
            "min_difference": MIN_DIFFERENCE,
        }


def prove_run_out(
    images: Sequence[NDArray[np.floating]], proof: NDArray[np.floating]
) -> RunOutProof:
    """Decide from the run's images (in order, ``images[-1]`` = the last LED) and the proof
    frame shot after it whether the dome ran out exactly at the last image."""
    if len(images) < 2:
        raise ValueError("the proof needs the last two images of the order")
    n = len(images)
    same = relative_difference(images[-1], proof)
    neighbours = relative_difference(images[-2], images[-1])
    earlier = [relative_difference(images[k - 1], images[k]) for k in range(1, n - 1)]
    typical = float(np.median(earlier)) if earlier else float("nan")
    threshold = max(SAME_RATIO * same, MIN_DIFFERENCE)
    figures = (
        f"d(image {n}, proof frame) = {same:.4f}, d(image {n - 1}, image {n}) = {neighbours:.4f}"
    )
    if neighbours > threshold:
        return RunOutProof(
            PROVED,
            f"the proof frame re-lit image {n}'s LED and image {n - 1} was lit by another "
            f"({figures}): the dome ran out exactly at image {n}, so no step was doubled in "
            "the run",
            same,
            neighbours,
            typical,
        )
    if np.isfinite(typical) and typical > threshold:
        return RunOutProof(
            DOUBLE,
            f"image {n - 1} differs from image {n} no more clearly than the same LED twice does "
            f"({figures}; consecutive images of this run differ by {typical:.4f}, median): the "
            f"dome did not run out exactly at image {n}. Images {n - 1} and {n} were lit by "
            "the same, last LED: the dome stepped twice somewhere in the run, where the check "
            "did not see it (or the proof frame was lit by another LED than image "
            f"{n}: a step lost unseen)",
            same,
            neighbours,
            typical,
        )
    return RunOutProof(
        CANNOT,
        f"image {n - 1} differs from image {n} no more clearly than the same LED twice does "
        f"({figures}), but consecutive images of this run differ little anyway "
        f"({typical:.4f}, median): either the dome stepped twice somewhere in the run, or this "
        "object looks the same under the order's last two LEDs at this noise; the order cannot be "
        "verified",
        same,
        neighbours,
        typical,
    )
