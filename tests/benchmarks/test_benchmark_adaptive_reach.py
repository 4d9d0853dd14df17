"""The hedged starting layouts that benchmarks/adaptive_reach.py measures: 4 lights of the
default floor's homogeneous layout (so the default design stays exactly that layout), as many
as possible shared with the other floors' layouts."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.adaptive_reach import hedged_start, shared_three_start, start_functions
from rti_rig.app.usecases.adaptive import dome_start
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner.adaptive import DESIGN_DEFAULT_FLOOR
from rti_rig.planner.uniform import select_uniform_leds


def _dome(seed: int) -> DomeGeometry:
    cand = fibonacci_cap(240, 0.0, 90.0)
    keep = np.sort(np.random.default_rng(seed).choice(240, 216, replace=False))
    return DomeGeometry(cand[keep], tuple(f"c{i:03d}" for i in keep))


@pytest.mark.parametrize("n", [6, 9, 12, 18])
@pytest.mark.parametrize("seed", [0, 1])
def test_a_hedged_start_is_part_of_the_default_layout_and_shares_more(n: int, seed: int) -> None:
    dome = _dome(seed)
    default = {int(i) for i in select_uniform_leds(dome, n, DESIGN_DEFAULT_FLOOR)}
    partner = {int(i) for i in select_uniform_leds(dome, n, 20.0)}
    plain = dome_start(dome, 4, n)
    hedged = hedged_start(dome, 4, n, (20.0,))
    assert len(set(hedged)) == 4
    assert set(hedged) <= default
    assert len(set(hedged) & partner) >= len(set(plain) & partner)
    assert len(set(hedged) & partner) == min(4, len(default & partner))


def test_the_default_start_is_what_ships() -> None:
    dome = _dome(0)
    assert start_functions()["default"](dome, 4, 9) == dome_start(dome, 4, 9)


@pytest.mark.parametrize("n", [6, 9, 12, 18])
def test_the_three_light_start_belongs_to_both_layouts_or_is_the_shipped_one(n: int) -> None:
    dome = _dome(0)
    default = {int(i) for i in select_uniform_leds(dome, n, DESIGN_DEFAULT_FLOOR)}
    partner = {int(i) for i in select_uniform_leds(dome, n, 20.0)}
    start = shared_three_start(dome, 4, n)
    if len(default & partner) >= 3:
        assert len(start) == 3
        assert set(start) <= default & partner
    else:
        assert start == dome_start(dome, 4, n)
