"""``benchmarks.three_lights`` compares the layouts it names: the spiral as planned before
2026-12-04 and the triad the planner ships, and each layout's tilt figure as the plan says it."""

from __future__ import annotations

import numpy as np

from benchmarks.three_lights import spiral_leds, tolerances, triad_leds
from benchmarks.tradeoff import shipped_rig
from rti_rig.app.config import rig_geometry
from rti_rig.core.geometry import az_el_from_direction


def test_the_layouts_are_the_old_and_the_shipped_plans() -> None:
    dome = rig_geometry(shipped_rig("simulated_dome.toml"))
    _, spiral = az_el_from_direction(dome.directions[spiral_leds(dome, 0.0)])
    _, triad = az_el_from_direction(dome.directions[triad_leds(dome, 0.0)])
    np.testing.assert_allclose(sorted(spiral), [10.0, 40.0, 55.0], atol=0.01)
    np.testing.assert_allclose(triad, 40.0, atol=0.01)


def test_the_turn_turns_both_layouts() -> None:
    dome = rig_geometry(shipped_rig("simulated_dome.toml"))
    for pick in (spiral_leds, triad_leds):
        assert set(pick(dome, 0.0)) != set(pick(dome, 90.0))


def test_the_tilt_figures_are_the_plans() -> None:
    lines = " ".join(tolerances())
    assert "`simulated_dome.toml`: spiral at 10°, 40°, 55°, tilt tolerated 0°" in lines
    assert "triad at 40°, 40°, 40°, tilt tolerated 30°" in lines
    assert "`virtual_arm.toml`: spiral at 14°, 32°, 57°, tilt tolerated 5°" in lines
    assert "triad at 35°, 35°, 35°, tilt tolerated 25°" in lines
