"""N unknown (`--until-error` alone): the light is chosen within the design of the guessed N."""

from __future__ import annotations

import numpy as np
from adaptive_states import state_for

from rti_rig.core.geometry import fibonacci_cap
from rti_rig.planner.adaptive import DESIGN_FLOORS, homogeneous_completion
from rti_rig.planner.adaptive_until import choose_until, guessed_lights


def _fit_unused(*_args, **_kwargs):  # the state has no observations: the bound scores
    raise AssertionError("no object model without observations")


def test_the_light_is_one_of_the_guessed_designs_and_the_guess_is_recorded() -> None:
    cands = fibonacci_cap(60, 5.0)
    rng = np.random.default_rng(0)
    normals = np.column_stack([rng.normal(0, 0.2, (300, 2)), np.ones(300)])
    for shot in ([3, 17, 31, 45, 52], [3, 17, 31, 45, 52, 8, 24]):
        state = state_for(normals, cands[shot])
        available = np.ones(len(cands), dtype=bool)
        available[shot] = False
        d = choose_until(state, cands, available, 60, fit=_fit_unused)
        guess = guessed_lights(len(shot), 60)
        assert d.guessed_lights == guess and d.evidence()["guessed_lights"] == guess
        designs = [
            homogeneous_completion(cands, available, cands[shot], guess, f) for f in DESIGN_FLOORS
        ]
        assert any(c is not None and d.candidate in c for c in designs)
        assert f"design of {guess} lights" in d.reason
    assert guessed_lights(5, 60) == 6 and guessed_lights(7, 60) == 9
