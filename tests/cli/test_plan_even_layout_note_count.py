"""The note that an even layout did as well says what was seen at the plan's own count.

Before: a plan of 12 lights was told "for brushed metal at 20 lights or more, an even layout
… did better", a finding at 20 and 30 lights, not at 12.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app


def _note(tmp_path: Path, lights: int) -> str:
    out = tmp_path / f"p{lights}.lp"
    argv = ["plan", "--rig", str(CONFIGS / "simulated_dome.toml"), "--lights", str(lights)]
    r = CliRunner().invoke(app, [*argv, "--method", "optimal", "--out", str(out)])
    assert r.exit_code == 0, said(r)
    (line,) = said(r).split("from 12 lights the planner")[1:]
    return line


@pytest.mark.parametrize("lights", [12, 16])
def test_below_twenty_lights_no_brushed_metal_finding(tmp_path: Path, lights: int) -> None:
    note = _note(tmp_path, lights)
    assert "brushed metal" not in note and "did better" not in note, note
    assert "an even layout from a 10° floor is worth comparing (rti-rig plan" in note, note


def test_from_twenty_lights_the_finding_is_said(tmp_path: Path) -> None:
    note = _note(tmp_path, 20)
    assert "for brushed metal at 20 lights or more, an even layout from a 10° floor did" in note
