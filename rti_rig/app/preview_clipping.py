"""What a clipped preview costs the plan, said before the lights are planned from it.

Why: the planner reads the object's relief from the preview's shading (shape from shading, or
a monocular depth model), and a clipped pixel has none: a preview whose brightest two thirds
clipped was planned from without a word, its relief flat where the object is brightest (a
16-bit preview clipped at 65535, and a 12-bit camera's clipped at 4095 alike). The clip level
is the file's top code (255, 65535), or the one a pile of pixels shows in a 16-bit file
(:func:`rti_rig.reconstruct.full_scale.full_scale_of`, as ``rti-rig fit`` reads it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.shell_words import shown_path
from rti_rig.reconstruct.full_scale import full_scale_of
from rti_rig.reconstruct.signal_check import sample_grid

#: The share of the preview's pixels clipped from which the plan says so: a glossy object's
#: highlights (a few %) cost the relief little; beyond this, whole regions have no shading.
PREVIEW_CLIPPED_LIMIT = 0.05
#: Pixels sampled to read a 16-bit preview's clip level.
SAMPLE_PIXELS = 100_000


def preview_clipped_note(path: Path, image: NDArray, meter: str | None = None) -> str | None:
    """The note on ``image`` (the preview's codes as its file stores them, before any colour
    conversion: the clip is the camera's) when more than :data:`PREVIEW_CLIPPED_LIMIT` of its
    pixels are clipped in every channel, else None. ``meter``: the command that shoots a
    metered preview on this rig (None: no rig config to name).

    Every channel, not any: the planner reads brightness, a weighted sum of the channels, and a
    vivid red object's red channel at its top code leaves the shading in green and blue."""
    img = np.asarray(image)
    if img.dtype == np.uint8:
        top = 255
    elif img.dtype == np.uint16:
        rows, cols = sample_grid(img.shape[0], img.shape[1], SAMPLE_PIXELS)
        sample = img[rows[:, None], cols[None, :]].reshape(1, rows.size * cols.size, -1)
        full = full_scale_of(sample, [path.name])
        top = full.level if full is not None and full.how == "clipped" else 65535
    else:
        return None  # float data: no clip level known
    at_top = img >= top
    share = float((at_top.all(axis=2) if at_top.ndim == 3 else at_top).mean())
    if share <= PREVIEW_CLIPPED_LIMIT:
        return None
    metered = f" ({meter} meters one)" if meter else ""
    return (
        f"{shown_path(path)}: {share:.0%} of the preview's pixels are clipped (at {top} in "
        "every channel), on the object or its background: where they are on the object its "
        "shading is lost, so the relief read from it is flat there (the plan's expected "
        "errors are reckoned on that relief, and with --method kmeans or optimal its lights "
        f"too); shoot the preview with less exposure{metered} and plan again"
    )
