"""fit.rti's HSH order from held-out evidence: the lowest order within the tolerance of the
best, what is asked for wins, an HSH model is written as chosen, and no evidence, no order."""

from __future__ import annotations

from rti_rig.app.usecases.fit_rti_order import hsh_order
from rti_rig.reconstruct.model_select import CandidateEvidence, ModelChoice


def _choice(rmse: dict[str, float | None]) -> ModelChoice:
    terms = {"lambert": 3, "hsh1": 4, "ptm": 6, "hsh2": 9, "hsh3": 16}
    evidence = tuple(
        CandidateEvidence(m, terms[m], r, None, False, 0, 5, "") for m, r in rmse.items()
    )
    return ModelChoice("lambert", 3, "lambert", 0.05, "5-fold", 100, evidence)


def test_the_lowest_order_within_the_tolerance_of_the_best_hsh() -> None:
    near = _choice({"lambert": 0.09, "hsh1": 0.100, "ptm": 0.2, "hsh2": 0.097, "hsh3": None})
    assert hsh_order(None, "lambert", near, 12)[0] == 1  # order 2 is better by under 5 %
    far = _choice({"lambert": 0.09, "hsh1": 0.100, "ptm": 0.2, "hsh2": 0.090, "hsh3": 0.094})
    order, why = hsh_order(None, "lambert", far, 20)
    assert order == 2 and why.startswith("hsh2: the lowest HSH order within 5%")


def test_asked_and_chosen_orders_win_and_no_evidence_gives_none() -> None:
    choice = _choice({"hsh1": 0.1, "hsh2": 0.05})
    assert hsh_order(3, "lambert", choice, 20) == (3, "hsh3: asked for")
    assert hsh_order(None, "hsh2", choice, 20) == (2, "hsh2: the model chosen")
    order, why = hsh_order(None, "ps", None, 4)
    assert order is None and why.startswith("fit.rti not written") and "--hsh-order 1" in why
    unscored = _choice({"hsh1": None, "hsh2": None})
    assert hsh_order(None, "lambert", unscored, 4)[0] is None
