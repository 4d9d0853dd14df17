"""A plan refused for too few lights in the band never advises a count a plan refuses.

With one LED at or above the floor, `rti-rig plan` had said "use --lights 1 or fewer", and
`--lights 1` is refused ("give at least 3 lights to plan"); a rig of 2 lights was told "use
--lights 2".
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, write_lp


def _plan(tmp_path: Path, lights: list[tuple[float, float, float]], *extra: str) -> str:
    rig = tmp_path / "rig.lp"
    write_lp(rig, [LpEntry(f"led_{k:02d}.jpg", d) for k, d in enumerate(lights)])
    r = CliRunner().invoke(
        app, ["plan", "--rig", str(rig), "--lights", "3", "--out", str(tmp_path / "p.lp"), *extra]
    )
    assert r.exit_code == 2, r.output
    return " ".join(r.output.split())


def _at(el_deg: float, az_deg: float) -> tuple[float, float, float]:
    e, a = np.radians(el_deg), np.radians(az_deg)
    return (float(np.cos(e) * np.cos(a)), float(np.cos(e) * np.sin(a)), float(np.sin(e)))


def test_one_led_above_the_floor_is_not_advised_as_a_count(tmp_path: Path) -> None:
    said = _plan(
        tmp_path, [_at(30, 0), _at(30, 120), _at(30, 240), _at(86, 0)], "--min-elevation-deg", "80"
    )
    assert "use --lights 1" not in said
    assert "widen --min-elevation-deg" in said


def test_a_rig_of_two_lights_is_told_a_plan_needs_three(tmp_path: Path) -> None:
    said = _plan(tmp_path, [_at(30, 0), _at(60, 120)])
    assert "use --lights 2" not in said
    assert "a plan needs at least 3 lights" in said
