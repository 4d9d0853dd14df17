"""The HSH order of the fit.rti `rti-rig fit` writes, and why.

Why a module of its own: the order is chosen from the model choice's held-out evidence, and the
adaptive session's advice (how many lights a session needs for an .rti) must name the same
fewest lights the fit writes one from, without importing the fit.
"""

from __future__ import annotations

from typing import Any

#: The fewest lights an auto fit writes fit.rti from: its 5-fold cross-validation leaves HSH of
#: order 1 its 4 fitting lights from 5 lights on, so its held-out error is measured from there.
HSH_FEWEST_LIGHTS = 5


def hsh_order(asked: int | None, model: str, choice: Any, n: int) -> tuple[int | None, str]:
    """The HSH order fit.rti is written in, and why (a line for fit.json and the CLI).

    ``asked`` (``--hsh-order``) wins; an HSH model chosen (by ``--model`` or by ``auto``'s
    evidence) is written as chosen. Otherwise — ``auto`` chose Lambert or the PTM, or
    ``--model`` named a model that is not HSH — the order is chosen from held-out evidence
    (``choice``: the model choice's, or one over the HSH orders alone), the lowest order within
    the tolerance of the best HSH order's held-out error, instead of a fixed order 2: a 6- to
    8-light session (what the planner and ``--adaptive`` often shoot) then gets a 4-term
    fit.rti, where order 2 (9 terms) cannot be fitted and no fit.rti was written; and at 9–11
    lights the folds cannot fit order 2 (it needs 9 fitting lights), so nothing supports it
    and order 1 is written — order 2 on 9 lights interpolates them exactly (on the shared real
    acquisition's homogeneous layouts of 9 it relit held-out lights at 15.4–16.3 dB, order 1
    at 20.4–22.1 dB). With no evidence (fewer than :data:`HSH_FEWEST_LIGHTS` lights) there is
    no fit.rti, and the reason says so.
    """
    if asked:
        return asked, f"hsh{asked}: asked for"
    if model.startswith("hsh"):
        return int(model[-1]), f"{model}: the model chosen"
    if choice is not None:
        scored = [e for e in choice.evidence if e.model.startswith("hsh") and e.rmse is not None]
        if scored:
            best = min(e.rmse for e in scored)
            pick = min(
                (e for e in scored if e.rmse <= best * (1.0 + choice.tolerance)),
                key=lambda e: e.n_coefficients,
            )
            return int(pick.model[-1]), (
                f"{pick.model}: the lowest HSH order within {choice.tolerance:.0%} of the best "
                f"HSH held-out error ({model}, the model used, is not an HSH)"
            )
    return None, (
        f"fit.rti not written: an HSH order is chosen on held-out lights, which needs at least "
        f"{HSH_FEWEST_LIGHTS} lights; there are {n} (--hsh-order 1 writes order 1 from 4)"
    )
