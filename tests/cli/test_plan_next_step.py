"""``plan`` ends with the ``run`` that shoots it, and that command runs as printed.

Before: ``plan`` ended at "Planned 12 lights (optimal, normals) → plan.lp"; ``preview`` and
``run`` each print the command that comes next, and the step between them did not.
"""

from __future__ import annotations

import shlex
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, write_lp

REPO = Path(__file__).resolve().parents[2]
DOME = str(REPO / "rig_configs" / "simulated_dome.toml")
runner = CliRunner()


def _next(args: list[str]) -> list[str]:
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    lines = [ln for ln in r.output.splitlines() if ln.startswith("Next: rti-rig ")]
    assert len(lines) == 1, r.output
    return shlex.split(lines[0].removeprefix("Next: rti-rig "))


def test_a_plan_from_a_preview_names_the_previews_rig_and_runs_as_printed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, ["preview", DOME, "--out", "P"])
    assert r.exit_code == 0, r.output
    (tmp_path / "planned").mkdir()  # taken: the command names a free folder
    line = _next(["plan", "P", "--lights", "6", "--out", "my plan.lp"])  # no --rig: P's rig
    assert line == ["run", DOME, "--plan", "my plan.lp", "--out", "planned-2"], line
    r = runner.invoke(app, [*line, "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len((tmp_path / "planned-2" / "lights.lp").read_text().splitlines()) == 7


def test_lights_planned_without_normals_are_run_with_the_same_option(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    ring = tmp_path / "ring.lp"  # 20 LEDs at the horizon: no choice of them determines normals
    az = np.radians(np.arange(20) * 18.0)
    write_lp(
        ring, [LpEntry(f"led_{k:02d}.jpg", (np.cos(a), np.sin(a), 0.0)) for k, a in enumerate(az)]
    )
    line = _next(["plan", "--rig", str(ring), "--lights", "6", "--allow-no-normals"])
    # a bare .lp with no config listing it: RIG.toml, the word left to fill in
    assert line == [
        "run",
        "RIG.toml",
        "--plan",
        "plan.lp",
        "--out",
        "planned",
        "--allow-no-normals",
    ]
    # lights that determine normals: the option is not needed, and not said
    line = _next(["plan", "--rig", DOME, "--lights", "6", "--out", "p2.lp", "--allow-no-normals"])
    assert "--allow-no-normals" not in line, line
    r = runner.invoke(app, [*line, "--no-verdict"])
    assert r.exit_code == 0, r.output
