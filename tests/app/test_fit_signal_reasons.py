"""The no-signal warning's "the N others ..." clause is built from what each reason is, not
from how it is worded.

Its grammar had been chosen by the reason's first word (``startswith("cannot")``): a reason
reworded "can't determine ..." would have been said "are can't determine ...". The CLI's
sentences are held by tests/cli/test_fit_no_signal_no_qa.py.
"""

from __future__ import annotations

from rti_rig.app.usecases.fit_signal import Shortfall, others_clause

FEWER = Shortfall("fewer than fit.ptm's 6 coefficients per pixel", complement=True)
NO_NORMAL = Shortfall("cannot determine a normal by themselves", complement=False)


def test_the_clause_as_the_fit_says_it() -> None:
    assert others_clause(2, [FEWER, NO_NORMAL]) == (
        "; the 2 others are fewer than fit.ptm's 6 coefficients per pixel and cannot "
        "determine a normal by themselves"
    )
    assert (
        others_clause(1, [FEWER])
        == "; the 1 other is fewer than fit.ptm's 6 coefficients per pixel"
    )
    assert others_clause(5, []) == ""


def test_a_reworded_reason_keeps_its_grammar() -> None:
    verb = Shortfall("can't determine a normal by themselves", complement=False)
    assert others_clause(3, [verb]) == "; the 3 others can't determine a normal by themselves"
