"""The HSH order of the fit.rti `rti-rig fit` writes, and why.

Why a module of its own: the order is chosen from the model choice's held-out evidence, and the
adaptive session's advice (how many lights a session needs for an .rti) must name the same
fewest lights the fit writes one from, without importing the fit.
"""

from __future__ import annotations

from typing import Any

from rti_rig.core.fit_minimums import FIT_MINIMUMS

#: The fewest lights an auto fit writes fit.rti from: its 5-fold cross-validation leaves HSH of
#: order 1 its 4 fitting lights from 5 lights on, so its held-out error is measured from there
#: (``FitMinimums.rti``: HSH order 1's coefficients plus one held out).
HSH_FEWEST_LIGHTS = FIT_MINIMUMS.rti


def hsh_order(
    asked: int | None,
    model: str,
    choice: Any,
    n: int,
    clipped: Any = None,
    clipped_share: float = 0.0,
) -> tuple[int | None, str]:
    """The HSH order fit.rti is written in, and why (a line for fit.json and the CLI).

    ``asked`` (``--hsh-order``) wins; then ``clipped`` (below); an HSH model chosen (by ``--model``
    or by ``auto``'s evidence) is written as chosen. Otherwise — ``auto`` chose Lambert or the PTM,
    or ``--model`` named a model that is not HSH — the order is chosen from held-out evidence
    (``choice``: the model choice's, or one over the HSH orders alone), the lowest order within the
    tolerance of the best HSH order's held-out error, instead of a fixed order 2: a 6- to 8-light
    session (what the planner and ``--adaptive`` often shoot) then gets a 4-term fit.rti, where
    order 2 (9 terms) cannot be fitted and no fit.rti was written; and at 9–11 lights the folds
    cannot fit order 2 (it needs 9 fitting lights), so nothing supports it and order 1 is written —
    order 2 on 9 lights interpolates them exactly (on the shared real acquisition's homogeneous
    layouts of 9 it relit held-out lights at 15.4–16.3 dB, order 1 at 20.4–22.1 dB). With no
    evidence (fewer than :data:`HSH_FEWEST_LIGHTS` lights) there is no fit.rti, and the reason says
    so.

    ``clipped``: the HSH orders' held-out evidence on the same pixel sample with the clipped
    observations kept, given where the model choice left pixels out as saturated (``clipped_share``
    of the sampled pixels clip in some image): the order is then chosen on it. Why: the model choice
    drops every pixel saturated in *any* image (a clipped value cannot be held out honestly), which
    on a glossy object is most of it — 37–53 % of the shared real acquisition's pixels at 18–48
    lights — and judged on the matte rest a low order looks enough. The file itself is fitted on the
    clipped values, and a viewer shows them clipped: kept, the chosen order relit held-out lights
    0.99 dB below the best order in hindsight on average instead of 1.75 on that acquisition, 0.77
    instead of 1.12 on the simulator's five scenes, never worse on average on any of the six
    (``benchmarks.fit_rti_order_saturation``; docs/reconstruction.md).
    """
    if asked:
        return asked, f"hsh{asked}: asked for"
    if clipped is not None:
        picked = _from_evidence(
            clipped,
            f", with clipped observations kept ({clipped_share:.1%} of the sampled pixels clip "
            f"in some image; the model choice leaves them out, and {model}, the model used, was "
            "judged without them)",
        )
        if picked is not None:
            return picked
    if model.startswith("hsh"):
        return int(model[-1]), f"{model}: the model chosen"
    if choice is not None:
        picked = _from_evidence(choice, f" ({model}, the model used, is not an HSH)")
        if picked is not None:
            return picked
    return None, (
        f"fit.rti not written: an HSH order is chosen on held-out lights, which needs at least "
        f"{HSH_FEWEST_LIGHTS} lights; there are {n} (--hsh-order 1 writes order 1 from 4)"
    )


def _from_evidence(choice: Any, why: str) -> tuple[int, str] | None:
    """The lowest HSH order of ``choice``'s evidence within its tolerance of the best HSH
    order's held-out error, and the reason (``why`` appended); None where no HSH order was
    scored."""
    scored = [e for e in choice.evidence if e.model.startswith("hsh") and e.rmse is not None]
    if not scored:
        return None
    best = min(e.rmse for e in scored)
    pick = min(
        (e for e in scored if e.rmse <= best * (1.0 + choice.tolerance)),
        key=lambda e: e.n_coefficients,
    )
    return int(pick.model[-1]), (
        f"{pick.model}: the lowest HSH order within {choice.tolerance:.0%} of the best HSH "
        f"held-out error{why}"
    )
