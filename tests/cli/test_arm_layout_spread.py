"""An arm's even layout is spread within the azimuths the arm reaches, not bunched at its limits.

Why: the layout's azimuths beyond the shipped emulated arm's ±170° were moved onto the limit:
of 24 lights, those that fell in the 20° it cannot reach were all lit at exactly ±170°.
Run through ``plan`` and ``run`` on the shipped config.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.lp_format import read_lp

runner = CliRunner(env={"COLUMNS": "400"})
ARM = str(CONFIGS / "simulated_arm.toml")  # azimuth joint -170°..170°


def _azimuths(lp: Path) -> np.ndarray:
    dirs = np.array([e.direction for e in read_lp(lp, upper_hemisphere=True)])
    az = az_el_from_direction(dirs)[0]
    return np.where(az > 180.0, az - 360.0, az)


def _spread_within_reach(az: np.ndarray) -> None:
    assert np.all(np.abs(az) <= 170.0 + 1e-6), az
    at_limit = np.abs(np.abs(az) - 170.0) < 0.5
    assert at_limit.sum() <= 1, np.sort(az)
    gaps = np.diff(np.sort(az))
    assert gaps.min() > 1.0, np.sort(az)  # no two lights at one azimuth


def test_plan_spreads_an_arm_layout_within_its_azimuths(tmp_path: Path) -> None:
    out = tmp_path / "p.lp"
    argv = ["plan", "--rig", ARM, "--lights", "24", "--method", "uniform", "--out", str(out)]
    r = runner.invoke(app, argv)
    assert r.exit_code == 0, said(r)
    _spread_within_reach(_azimuths(out))


def test_run_spreads_an_arm_layout_within_its_azimuths(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", ARM, "--lights", "24", "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, said(r)
    az = _azimuths(out / "lights.lp")
    assert len(az) == 24
    _spread_within_reach(az)
