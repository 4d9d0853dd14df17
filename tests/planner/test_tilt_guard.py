"""The exchange's tilt guard: a plan is not allowed to lose a point to a tilt the even layouts
it was compared with would have survived.

Why: on the simulated 50°-tilted plane, `plan --method optimal` at 4–5 lights chose lights at
24–34° elevation, two behind the plane, and solved nothing (49.8° mean error in 2 of 6 draws
against 0.25° for an even layout); the written plan of the shipped simulated dome at 4 lights
kept 3 lights facing the object only up to a 15° tilt (the even layouts it was compared with:
45°; the guard asks for up to 40°).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import REPO
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.planner.tilt_guard import (
    MAX_GUARD_DEG,
    NEED_LIT,
    TiltGuard,
    tilt_guard,
    tilt_tolerance,
    tilted_planes,
)

UP = np.array([0.0, 0.0, 1.0])


def _ring(elevation_deg: float, count: int, offset_deg: float = 0.0) -> np.ndarray:
    el = np.radians(elevation_deg)
    az = np.radians(offset_deg + 360.0 * np.arange(count) / count)
    return np.stack(
        [np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.full(count, np.sin(el))], 1
    )


def test_tilted_planes_are_unit_and_as_far_from_up_as_asked() -> None:
    planes = tilted_planes(UP, 20.0)
    assert np.allclose(np.linalg.norm(planes, axis=1), 1.0)
    tilts = np.degrees(np.arccos(np.clip(planes @ UP, -1, 1)))
    assert tilts[0] == pytest.approx(0.0, abs=1e-9)
    assert sorted(set(np.round(tilts).astype(int))) == [0, 5, 10, 15, 20]


def test_high_lights_survive_every_checked_tilt_and_low_ones_do_not() -> None:
    # a light at elevation e faces a plane tilted by t in any direction while 90 - e + t stays
    # short of grazing: three at 80° survive 60°, three at 20° lose one behind a 15° tilt
    assert tilt_tolerance(_ring(80.0, 3), UP, max_deg=60.0) == 60.0
    low = tilt_tolerance(_ring(20.0, 3), UP)
    assert 0.0 <= low <= 10.0
    # more lights round the same ring tolerate more
    assert tilt_tolerance(_ring(30.0, 6), UP, 60.0) > tilt_tolerance(_ring(30.0, 4), UP, 60.0)


def test_a_level_plane_faced_by_fewer_than_three_lights_has_no_tolerance() -> None:
    assert tilt_tolerance(_ring(45.0, 2), UP) == -1.0
    assert tilt_guard(_ring(45.0, 2), UP, [np.arange(2)]) is None


def test_allowed_says_exactly_which_swaps_keep_the_guard() -> None:
    rng = np.random.default_rng(3)
    v = rng.normal(size=(60, 3))
    v[:, 2] = np.abs(v[:, 2])
    candidates = v / np.linalg.norm(v, axis=1, keepdims=True)
    lit = (tilted_planes(UP, 30.0) @ candidates.T) > 0.15
    guard = TiltGuard(lit, 30.0)
    checked = 0
    for _ in range(40):
        chosen = rng.choice(60, 6, replace=False)
        for pos in range(6):
            allowed = guard.allowed(chosen, pos)
            for k in range(60):
                trial = chosen.copy()
                trial[pos] = k
                assert allowed[k] == guard.holds(trial)
                checked += 1
    assert checked == 40 * 6 * 60
    assert NEED_LIT == 3


@pytest.mark.e2e
@pytest.mark.parametrize(("lights", "tolerance"), [(4, MAX_GUARD_DEG), (5, MAX_GUARD_DEG)])
def test_an_optimal_plan_on_the_shipped_dome_keeps_the_tilt_its_even_layouts_survive(
    tmp_path: Path, lights: int, tolerance: float
) -> None:
    out = tmp_path / "plan.lp"
    config = REPO / "rig_configs" / "simulated_dome.toml"
    r = CliRunner().invoke(
        app,
        [
            "plan",
            "--rig",
            str(config),
            "--method",
            "optimal",
            "--lights",
            str(lights),
            "--out",
            str(out),
        ],
    )
    assert r.exit_code == 0, r.output
    directions = np.loadtxt(out, skiprows=1, usecols=(1, 2, 3))
    assert len(directions) == lights
    assert tilt_tolerance(directions, UP) >= tolerance
    text = " ".join(r.output.split())
    assert f"if the object is tilted up to {tolerance:g}° in any direction" in text, text
