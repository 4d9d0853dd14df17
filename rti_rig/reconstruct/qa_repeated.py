"""One picture under two lights: an image that is, pixel for pixel, an earlier one of the
same acquisition, judged on the QA's reduced images.

Why: a frame delivered twice (a camera that missed its trigger and returned its last picture,
a stale frame from a capture buffer, a file copied over another in an exported acquisition)
passed ``check``, ``run`` and ``fit`` with "QA verdict: good": the other checks compare each
image with the fit, and one repeated image among many moves the fit too little to stand out.
Two real photographs are never equal to the last bit (the camera's noise differs between any
two exposures), nor are two renders of a surface under two lights; an image of one level (a
black frame) is left to the checks that name it.
"""

from __future__ import annotations

import hashlib

import numpy as np
from numpy.typing import NDArray

from rti_rig.reconstruct.qa_unchanging import FLAT_ADVICE

#: How the verdict begins the problem of a repeated image.
REPEATED = "the same picture as"


def repeated_pictures(small: NDArray[np.float32]) -> dict[int, int]:
    """``{later: first}``: each reduced image (of ``small``, N×h×w) equal to an earlier one,
    with the index of the first of them; images of one level are never matched."""
    first: dict[bytes, int] = {}
    same: dict[int, int] = {}
    for i, image in enumerate(small):
        if float(image.max()) == float(image.min()):
            continue
        key = hashlib.blake2b(np.ascontiguousarray(image).tobytes(), digest_size=16).digest()
        if key in first:
            same[i] = first[key]
        else:
            first[key] = i
    return same


def repeated_problem(first: str) -> str:
    """What the verdict says of an image that is the picture of ``first`` again."""
    return (
        f"{REPEATED} {first}, though another light lit it (a frame delivered twice: a camera "
        f"that missed its trigger or returned a stale frame, or a file copied over); "
        f"{FLAT_ADVICE}"
    )
