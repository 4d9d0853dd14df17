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

#: Without evidence (a model named by ``--model`` that is not HSH), the HSH order of fit.rti:
#: the highest whose coefficients this many lights determine with some to spare (1.5× the
#: coefficients, as the planner's ``MODEL_MIN_LIGHTS``; order 2's 9 terms are kept from 9
#: lights, as before).
HSH_ORDER_MIN_LIGHTS = {2: 9, 1: 6}


def hsh_order(asked: int | None, model: str, choice: Any, n: int) -> tuple[int | None, str]:
    """The HSH order fit.rti is written in, and why (a line for fit.json and the CLI).

    An HSH model chosen (by ``--model`` or by the evidence) is written as chosen. When ``auto``
    chose another model (Lambert or the PTM, which are not HSH), the HSH order is still chosen
    from the same held-out evidence — the lowest order within the tolerance of the best HSH
    order's held-out error — instead of a fixed order 2: a 6- or 8-light session (what the
    planner and ``--adaptive`` often shoot) then gets a 4-term fit.rti, where order 2 (9 terms)
    cannot be fitted and no fit.rti was written; and at 9–11 lights the folds cannot fit order
    2 (it needs 9 fitting lights), so nothing supports it and order 1 is written — order 2 on
    9 lights interpolates them exactly (on the shared real acquisition's homogeneous layouts of
    9 it relit held-out lights at 15.4–16.3 dB, order 1 at 20.4–22.1 dB).
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
                f"HSH held-out error ({model} was chosen, which fit.rti cannot hold)"
            )
    for order, lights in HSH_ORDER_MIN_LIGHTS.items():
        if n >= lights:
            return order, (
                f"hsh{order}: the default order without held-out evidence (--model {model}; "
                f"order 2 from {HSH_ORDER_MIN_LIGHTS[2]} lights, else 1 from "
                f"{HSH_ORDER_MIN_LIGHTS[1]})"
            )
    return None, (
        f"fit.rti not written: {n} lights are too few for an HSH fit without held-out evidence "
        f"(order 1 is written from {HSH_ORDER_MIN_LIGHTS[1]} lights; --model auto measures it "
        f"from {HSH_FEWEST_LIGHTS})"
    )
