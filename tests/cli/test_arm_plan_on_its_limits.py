"""A plan with lights exactly on an arm's limits, as an `.lp` stores them, runs on the arm.

A light planned on the 15° keep-out edge was refused as "15.00° from the camera axis, inside
the 15° keep-out cone; the plan was made for another rig": the `.lp`'s six decimals had put it
1e-4° inside. A light really inside the cone is still refused before anything moves.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.lp_format import LpEntry, format_lp, read_lp

runner = CliRunner()


def _plan(path: Path, az_el: list[tuple[float, float]]) -> Path:
    entries = [
        LpEntry(f"image_{i + 1:03d}.jpg", tuple(np.round(direction_from_az_el(az, el), 6)))
        for i, (az, el) in enumerate(az_el)
    ]
    path.write_text(format_lp(entries))
    return path


def test_lights_on_the_keep_out_edge_and_the_azimuth_stops_run(tmp_path: Path) -> None:
    # simulated_arm.toml: keep-out half angle 15°, azimuth -170..170, elevation from 0°
    edge = [(10.0, 75.0), (170.0, 30.0), (-170.0, 30.0), (-100.0, 75.0), (45.0, 0.0)]
    plan = _plan(tmp_path / "edge.lp", edge)
    out = tmp_path / "s"
    args = ["run", str(CONFIGS / "simulated_arm.toml"), "--plan", str(plan), "--out", str(out)]
    r = runner.invoke(app, [*args, "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(read_lp(out / "lights.lp")) == 5

    inside = _plan(tmp_path / "inside.lp", [*edge[:4], (10.0, 75.02)])
    r = runner.invoke(app, [*args[:2], "--plan", str(inside), "--out", str(tmp_path / "t")])
    assert r.exit_code == 2, r.output
    assert "inside the 15° keep-out cone" in said(r)
