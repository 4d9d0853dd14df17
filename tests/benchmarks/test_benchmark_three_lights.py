"""``benchmarks.three_lights`` compares the layouts it names: the spiral as planned before
2026-12-04 and the triad the planner ships, and each layout's tilt figure as the plan says it."""

from __future__ import annotations

import numpy as np
import pytest

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


def test_the_arm_layouts_are_the_ones_named() -> None:
    """On an arm turning ±90°: the spiral and the triad mapped as they were planned before,
    the least bound with none below the triad's elevation, and the arm's plan as it ships."""
    from benchmarks.three_lights import arm_layouts, turned
    from rti_rig.core.rig_geometry import ArmGeometry

    arm = ArmGeometry(0.0, 90.0, 15.0, 0.0, 10.0, -90.0, 90.0)
    layouts = arm_layouts(arm)
    assert list(layouts) == ["spiral", "mapped triad", "least bound", "ships"]
    for lights in layouts.values():
        assert arm.reachable(lights).all()

    def bound(lights: np.ndarray) -> float:
        return float(np.trace(np.linalg.inv(lights.T @ lights)))

    az, _ = az_el_from_direction(layouts["mapped triad"])
    np.testing.assert_allclose(np.sort(np.where(az > 180, az - 360, az)), [-60, 0, 60], atol=1e-9)
    assert bound(layouts["mapped triad"]) == pytest.approx(19.0)
    assert bound(layouts["least bound"]) < bound(layouts["ships"]) == pytest.approx(4.5)
    assert az_el_from_direction(layouts["least bound"])[1].min() >= 35.26 - 1e-6
    np.testing.assert_array_equal(layouts["ships"], arm.homogeneous(3))
    # a turn about the camera axis keeps each light's elevation and the layout's shape
    t = turned(layouts["ships"], 37.0)
    np.testing.assert_allclose(
        az_el_from_direction(t)[1], az_el_from_direction(layouts["ships"])[1]
    )
    ships = layouts["ships"]
    np.testing.assert_allclose(np.linalg.eigvalsh(t.T @ t), np.linalg.eigvalsh(ships.T @ ships))
    assert not np.allclose(t, ships)


def test_the_sparse_domes_alternative_is_the_most_tilt_tolerant_turn() -> None:
    """On the 12-LED elexol dome the triad at its fixed orientation takes a 17° LED (5° of
    tilt); the alternative measured against it keeps a normal to 25°."""
    from benchmarks.three_lights import tolerant_triad_leds
    from rti_rig.planner.tilt_guard import tilt_tolerance

    dome = rig_geometry(shipped_rig("emulated_elexol.toml"))
    up = np.array([0.0, 0.0, 1.0])
    ships = dome.directions[triad_leds(dome, 0.0)]
    tolerant = dome.directions[tolerant_triad_leds(dome, 0.0)]
    assert tilt_tolerance(ships, up) == 5.0
    assert tilt_tolerance(tolerant, up) == 25.0
    assert az_el_from_direction(ships)[1].min() == pytest.approx(17.0, abs=0.5)
