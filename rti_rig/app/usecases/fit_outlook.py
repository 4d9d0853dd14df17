"""What `rti-rig fit` will and will not make of a session of N lights, said before it is shot.

Why: ``run --lights 3`` said nothing and its QA verdict was "good", then plain ``fit`` failed
("--model auto: no candidate model can be fitted from 3 image(s)"); at 4 or 5 lights no word
said that no fit.ptm would be written (only an ``--until-error`` stop said so). The figures are
read from what the fit itself requires — ``core.fit_minimums``, which the fit's gates, the
model choice and the registry read too — never restated here.
"""

from __future__ import annotations

from rti_rig.core.fit_minimums import FIT_MINIMUMS, AutoFit


def fit_needs() -> str:
    """The fit's figures in one clause, for every refusal of too few lights (run, plan): the
    same words wherever they are said."""
    least = FIT_MINIMUMS
    return (
        f"`rti-rig fit` needs {least.normal} for a normal map with --model ps, {least.auto} for "
        f"its default --model auto, a PTM {least.ptm}, fit.rti {least.rti}"
    )


def fit_outlook(n: int, normals_determined: bool = True) -> str | None:
    """What a session of ``n`` lights gives `rti-rig fit` and what not, or None when it gives
    every file: something to know before the lights come on.

    ``normals_determined``: whether the lights can determine a surface normal
    (``app.normals_determined``); where they cannot, ``--model auto`` leaves photometric stereo
    out and needs more lights (:class:`~rti_rig.core.fit_minimums.AutoFit`, which the fit's own
    choice reads too). Why: 4 raking lights at one azimuth were told "will make a normal map",
    and the fit then made nothing."""
    least = FIT_MINIMUMS
    auto = AutoFit(n, normals_determined)
    lights = f"{n} light{'s' if n != 1 else ''}"
    full = f"for an RTI (fit.ptm and fit.rti) give --lights {least.rti_file} or more"
    if not normals_determined and n >= least.normal:
        return _undetermined_outlook(auto, lights)
    if n < least.normal:
        return (
            f"{lights}: too few for normals or any relighting fit (photometric stereo needs "
            f"{least.normal}, `rti-rig fit`'s default --model auto {least.auto}, a PTM "
            f"{least.ptm}); the images are kept, but `rti-rig fit` and the QA verdict will "
            f"have nothing to fit. Fine for a test shot; {full}"
        )
    if not auto.fits:
        return (
            f"{lights}: `rti-rig fit` with its default --model auto cannot fit them (its "
            f"simplest model needs {auto.least}: fitted, and checked on one left out); "
            f"only `rti-rig fit --model ps` makes a normal map of them, with no fit.ptm (a PTM "
            f"needs {least.ptm}) and no fit.rti (an HSH fit needs {least.rti}); {full}"
        )
    missing = [(f, what, k) for f, what, k in _FILES if not getattr(auto, k)]
    if not missing:
        return None
    files = " or ".join(f for f, _, _ in missing)
    needs = ", ".join(f"{what} needs {getattr(least, k)}" for _, what, k in missing)
    return f"{lights}: `rti-rig fit` will make a normal map but no {files} ({needs}); {full}"


def auto_way_out(auto: AutoFit) -> str:
    """What to do where ``--model auto`` fits nothing of lights that cannot determine a normal:
    how many more lights it needs, and the fit by name that writes a file of them now (an order-1
    HSH from its 4 coefficients). Said by the run's note and by the fit's refusal alike."""
    least = FIT_MINIMUMS
    more = auto.least - auto.n
    now = (
        f"`rti-rig fit --model hsh1` writes fit.rti of them now (ridge-regularised, its "
        f"{least.hsh(1)} coefficients with none to spare); "
        if auto.n >= least.hsh(1)
        else ""
    )
    return (
        f"{now}for --model auto add {more} more light{'s' if more != 1 else ''} "
        f"({auto.least} in all), for fit.ptm as well {least.rti_file} in all"
    )


def _undetermined_outlook(auto: AutoFit, lights: str) -> str | None:
    """:func:`fit_outlook` of lights that cannot determine a normal: no normal maps whatever the
    count, and fit.rti and fit.ptm from the counts auto needs without photometric stereo.
    Each names ``--model auto``: ``fit --model ps``'s refusal says it too, and of 5 lights it
    had said "`rti-rig fit` will make fit.rti", which ``fit --model ps`` does not."""
    least = FIT_MINIMUMS
    if not auto.fits:
        return (
            f"{lights} that cannot determine a normal: `rti-rig fit` with its default --model "
            f"auto cannot fit them (photometric stereo left out, its simplest model, "
            f"{auto.simplest}, needs {auto.least}: fitted, and checked on one left out): no "
            f"fit.rti, and no fit.ptm (a PTM needs {least.ptm}); "
            f"{auto_way_out(auto)}"
        )
    if not auto.ptm:
        more = least.ptm - auto.n
        return (
            f"{lights} that cannot determine a normal: `rti-rig fit` with its default --model "
            f"auto will make fit.rti (ridge-regularised) but no fit.ptm (a PTM needs "
            f"{least.ptm}); "
            f"for fit.ptm as well add {more} more light{'s' if more != 1 else ''}"
        )
    return None


#: The relighting files a fit writes: the file, what it holds, its field of :class:`FitMinimums`.
_FILES = (("fit.ptm", "a PTM", "ptm"), ("fit.rti", "an HSH fit", "rti"))


def fit_without_normals(n: int) -> str:
    """What ``rti-rig fit`` makes of ``n`` lights that give no normals: the general words
    (``normals_determined.fit_without_normals_words``) where ``--model auto`` writes both relighting
    files of them, else what it does write of ``n`` and what to do (:func:`fit_outlook`).

    Why: a run of 4 raking lights said both "fit.ptm and fit.rti only" and, in the next note,
    "will make a normal map"; `rti-rig fit` then made neither (without photometric stereo its
    simplest model needs 5 lights)."""
    from rti_rig.app.normals_determined import NO_NORMAL_MAPS, fit_without_normals_words

    outlook = fit_outlook(n, normals_determined=False)
    return fit_without_normals_words(n) if outlook is None else f"{NO_NORMAL_MAPS}): {outlook}"
