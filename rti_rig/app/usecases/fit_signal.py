"""The warning ``rti-rig fit`` gives where its outputs rest on images that hold no signal.

Why: with ``--no-qa`` an acquisition black throughout (a lens cap, lights that never fired) or
saturated throughout (an exposure far too long) had its normal maps written without a word: a
least-squares fit of nothing is still a normal map; with ``--no-normals`` too its fit.ptm and
fit.rti were. The QA, when it runs, names such images itself (so the fit asks for this only
with ``--no-qa``).

Each output is judged by what it needs: the normal maps, images whose lights determine a
normal; a relighting file, as many images as its model has coefficients. A relighting-only
acquisition (raking lights at two azimuths) with one black image had been told its fit.ptm
rested on images without signal because the 11 lit ones "cannot determine a normal", which
the relighting files never needed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from rti_rig.core.fit_minimums import NORMAL_MIN_LIGHTS
from rti_rig.reconstruct.stack import ImageStack

#: Images named in the warning before "and N more".
NO_SIGNAL_NAMED = 12
#: How the normal maps are named in the warning.
NORMAL_MAPS = "the normal maps"


@dataclass(frozen=True)
class Shortfall:
    """Why the images holding signal cannot make an output, and how it joins "the N others":
    a complement (``"fewer than ..."``) takes "is"/"are" before it, a verb phrase (``"cannot
    determine ..."``) stands as it is.

    Why: the grammar had been chosen by the reason's first word (``startswith("cannot")``), so
    rewording a reason ("can't determine ...", "too few for ...") changed the sentence built
    ("are can't determine ...")."""

    text: str
    complement: bool

    def said(self, plural: bool) -> str:
        """The reason as the predicate of "the N other(s)"."""
        if not self.complement:
            return self.text
        return f"{'are' if plural else 'is'} {self.text}"


def others_clause(lit: int, why: Sequence[Shortfall]) -> str:
    """``"; the N others are ... and cannot ..."``: what the ``lit`` images holding signal
    fall short of (empty where nothing is said of them)."""
    if not why:
        return ""
    others = "the 1 other" if lit == 1 else f"the {lit} others"
    return f"; {others} " + " and ".join(w.said(lit != 1) for w in why)


def no_signal_warning(
    stack: ImageStack,
    lights: np.ndarray,
    names: Sequence[str],
    sample_pixels: int,
    relighting: Mapping[str, str] | None = None,
    normals: bool = True,
) -> list[str]:
    """A warning where what the fit wrote rests on images that hold no signal (black or
    clipped on almost every sampled pixel), naming them and the outputs concerned.

    ``relighting`` maps each relighting file written ("fit.ptm", "fit.rti") to its registry
    model ("ptm", "hsh2"); ``normals`` says whether the normal maps were. Every output is
    named where every image is empty; otherwise a relighting file only where fewer images hold
    signal than its model has coefficients (it cannot be fitted from them), and the normal
    maps only where the images holding signal cannot determine a normal by themselves.

    Judged on the pixel sample of ``sample_pixels`` the model choice and the quantisation
    ranges read anyway (cached; one sampled pass where nothing read it), so it costs next to
    nothing however large the images. One black image among lit ones is a misfire the QA
    judges, and the dim low lights of a dome metered for a glint are lit as they should be:
    neither is said here while the other images suffice for every output.
    """
    from rti_rig.app.normals_determined import undetermined_normals
    from rti_rig.reconstruct.registry import model_spec
    from rti_rig.reconstruct.signal_check import BLACK_FRACTION, images_without_signal

    relighting = dict(relighting or {})
    if not relighting and not normals:
        return []
    sample, _ = stack.pixel_sample(sample_pixels)
    empty = images_without_signal(sample, stack.saturation_level)
    if empty is None or not empty.indices:
        return []
    lit = np.setdiff1d(np.arange(stack.n), empty.indices)
    everything = len(lit) == 0
    short = {
        name: model_spec(key).n_coefficients
        for name, key in sorted(relighting.items())
        if everything or len(lit) < model_spec(key).n_coefficients
    }
    no_normal = normals and (
        everything or len(lit) < NORMAL_MIN_LIGHTS or undetermined_normals(lights[lit]) is not None
    )
    if not short and not no_normal:
        return []
    label = [names[i] if i < len(names) else f"image {i + 1}" for i in range(stack.n)]
    listed = [f"{label[i]} ({kind})" for i, kind in zip(empty.indices, empty.kinds, strict=True)]
    more = len(listed) - NO_SIGNAL_NAMED
    shown = ", ".join(listed[:NO_SIGNAL_NAMED]) + (f" and {more} more" if more > 0 else "")
    if everything:
        which, left = f"every image ({stack.n}) is", ""
    else:
        verb = "is" if len(listed) == 1 else "are"
        which = f"{len(listed)} of the {stack.n} images {verb}"
        why: list[Shortfall] = []
        if short:
            needs = " and ".join(f"{name}'s {count}" for name, count in short.items())
            why.append(Shortfall(f"fewer than {needs} coefficients per pixel", complement=True))
        if no_normal:
            # one image left is "itself" ("the 1 other cannot determine a normal by themselves")
            own = "itself" if len(lit) == 1 else "themselves"
            why.append(Shortfall(f"cannot determine a normal by {own}", complement=False))
        left = others_clause(len(lit), why)
    made = [*short, *([NORMAL_MAPS] if no_normal else [])]
    said = ", ".join(made[:-1]) + " and " + made[-1] if len(made) > 1 else made[0]
    verb = "are" if len(made) > 1 or made[0] == NORMAL_MAPS else "is"
    return [
        f"{said} {verb} from images that hold no signal: {which} black (below "
        f"{BLACK_FRACTION:.1%} of full scale) or clipped at saturation on almost every sampled "
        f"pixel: {shown}{left}. Check the lens cap, that the lights fire and the exposure, then "
        "capture again (the QA, left out by --no-qa, judges each image)"
    ]
