"""The warning ``rti-rig fit`` gives where its outputs rest on images that hold no signal.

Why: with ``--no-qa`` an acquisition black throughout (a lens cap, lights that never fired) or
saturated throughout (an exposure far too long) had its normal maps written without a word: a
least-squares fit of nothing is still a normal map; with ``--no-normals`` too its fit.ptm and
fit.rti were. The QA, when it runs, names such images itself (so the fit asks for this only
with ``--no-qa``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rti_rig.reconstruct.stack import ImageStack

#: Images named in the warning before "and N more".
NO_SIGNAL_NAMED = 12


def no_signal_warning(
    stack: ImageStack,
    lights: np.ndarray,
    names: Sequence[str],
    sample_pixels: int,
    outputs: Sequence[str] = ("the normal maps",),
) -> list[str]:
    """A warning where ``outputs`` (what the fit wrote: "fit.ptm", "fit.rti", "the normal
    maps") rest on images that hold no signal (black or clipped on almost every sampled pixel),
    naming them; none where the images that do hold signal determine a normal by themselves.

    Judged on the pixel sample of ``sample_pixels`` the model choice and the quantisation
    ranges read anyway (cached; one sampled pass where nothing read it), so it costs next to
    nothing however large the images. One black image among lit ones is a misfire the QA
    judges, and the dim low lights of a dome metered for a glint are lit as they should be:
    neither is said here while the other images determine the normals.
    """
    from rti_rig.app.normals_determined import undetermined_normals
    from rti_rig.reconstruct.signal_check import BLACK_FRACTION, images_without_signal

    sample, _ = stack.pixel_sample(sample_pixels)
    empty = images_without_signal(sample, stack.saturation_level)
    if empty is None or not empty.indices:
        return []
    lit = np.setdiff1d(np.arange(stack.n), empty.indices)
    if len(lit) >= 3 and undetermined_normals(lights[lit]) is None:
        return []
    label = [names[i] if i < len(names) else f"image {i + 1}" for i in range(stack.n)]
    listed = [f"{label[i]} ({kind})" for i, kind in zip(empty.indices, empty.kinds, strict=True)]
    more = len(listed) - NO_SIGNAL_NAMED
    shown = ", ".join(listed[:NO_SIGNAL_NAMED]) + (f" and {more} more" if more > 0 else "")
    if len(listed) == stack.n:
        which, left = f"every image ({stack.n}) is", ""
    else:
        which = f"{len(listed)} of the {stack.n} images are"
        left = f"; the {len(lit)} others cannot determine a normal by themselves"
    made = list(outputs)
    said = ", ".join(made[:-1]) + " and " + made[-1] if len(made) > 1 else made[0]
    return [
        f"{said} are from images that hold no signal: {which} black (below "
        f"{BLACK_FRACTION:.1%} of full scale) or clipped at saturation on almost every sampled "
        f"pixel: {shown}{left}. Check the lens cap, that the lights fire and the exposure, then "
        "capture again (the QA, left out by --no-qa, judges each image)"
    ]
