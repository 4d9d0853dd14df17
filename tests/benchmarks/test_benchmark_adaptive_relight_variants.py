"""``benchmarks.adaptive_relight_variants``: an unknown variant is refused before anything runs,
and a variant's settings hold only for its own sessions (restored after each, so variants run
in one process do not leak into one another)."""

from __future__ import annotations

import pytest

from benchmarks import adaptive_relight_variants as variants
from rti_rig.planner import adaptive_relight
from rti_rig.planner import adaptive_relight_design as relight_design


def test_an_unknown_variant_is_refused_up_front(capsys) -> None:
    with pytest.raises(SystemExit) as caught:
        variants.main(["--variants", "floors,nope"])
    assert caught.value.code == 2
    assert "unknown variant 'nope'" in capsys.readouterr().err


@pytest.mark.parametrize("name", sorted(variants.VARIANTS))
def test_a_variant_sets_its_values_for_its_sessions_only(name: str) -> None:
    before = (adaptive_relight.RELIGHT_FITTED_DESIGN, relight_design.UNMODELLED_REL)
    seen = {}

    def session() -> None:
        for module, values in variants.VARIANTS[name]:
            seen.update({k: getattr(module, k) == v for k, v in values.items()})

    variants._run_variant(name, session)
    assert seen and all(seen.values())
    assert before == (adaptive_relight.RELIGHT_FITTED_DESIGN, relight_design.UNMODELLED_REL)
