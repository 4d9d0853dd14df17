"""What `rti-rig fit` will and will not make of a session of N lights, said before it is shot.

Why: ``run --lights 3`` said nothing and its QA verdict was "good", then plain ``fit`` failed
("--model auto: no candidate model can be fitted from 3 image(s)"); at 4 or 5 lights no word
said that no fit.ptm would be written (only an ``--until-error`` stop said so). The figures are
read from what the fit itself requires — ``core.fit_minimums``, which the fit's gates, the
model choice and the registry read too — never restated here.
"""

from __future__ import annotations

from rti_rig.core.fit_minimums import FIT_MINIMUMS


def fit_needs() -> str:
    """The fit's figures in one clause, for every refusal of too few lights (run, plan): the
    same words wherever they are said."""
    least = FIT_MINIMUMS
    return (
        f"`rti-rig fit` needs {least.normal} for a normal map with --model ps, {least.auto} for "
        f"its default --model auto, a PTM {least.ptm}, fit.rti {least.rti}"
    )


def fit_outlook(n: int) -> str | None:
    """What a session of ``n`` lights gives `rti-rig fit` and what not, or None when it gives
    every file: something to know before the lights come on."""
    least = FIT_MINIMUMS
    lights = f"{n} light{'s' if n != 1 else ''}"
    full = f"for an RTI (fit.ptm and fit.rti) give --lights {least.rti_file} or more"
    if n < least.normal:
        return (
            f"{lights}: too few for normals or any relighting fit (photometric stereo needs "
            f"{least.normal}, `rti-rig fit`'s default --model auto {least.auto}, a PTM "
            f"{least.ptm}); the images are kept, but `rti-rig fit` and the QA verdict will "
            f"have nothing to fit. Fine for a test shot; {full}"
        )
    if n < least.auto:
        return (
            f"{lights}: `rti-rig fit` with its default --model auto cannot fit them (its "
            f"simplest model needs {least.auto}: fitted, and checked on one left out); "
            f"only `rti-rig fit --model ps` makes a normal map of them, with no fit.ptm (a PTM "
            f"needs {least.ptm}) and no fit.rti (an HSH fit needs {least.rti}); {full}"
        )
    missing = [(f, what, k) for f, what, k in _FILES if n < getattr(least, k)]
    if not missing:
        return None
    files = " or ".join(f for f, _, _ in missing)
    needs = ", ".join(f"{what} needs {getattr(least, k)}" for _, what, k in missing)
    return f"{lights}: `rti-rig fit` will make a normal map but no {files} ({needs}); {full}"


#: The relighting files a fit writes: the file, what it holds, its field of :class:`FitMinimums`.
_FILES = (("fit.ptm", "a PTM", "ptm"), ("fit.rti", "an HSH fit", "rti"))
