"""A light on the edge of an elevation band, read from a dome's .lp, is in the band.

An .lp keeps six decimals: a 10° ring written so reads back at 9.99998°. The planner and
``run`` compared band edges to within 1e-9°, so on a dome described by its .lp, ``run
--min-elevation-deg 10`` shot 36 of 48 LEDs (the whole 10° ring left out without a word),
``--max-elevation-deg 70`` 42, and ``plan --method uniform --min-elevation-deg 10`` planned
from 25° up, while ``run --plan`` with the same band took every light. Through the CLI, on the
shipped emulated .lp dome given the simulated dome's five rings as its .lp.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.lp_format import read_lp

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _ring_dome(tmp_path: Path) -> Path:
    """The simulated dome's 48 LEDs (rings at 10, 25, 40, 55 and 70°) as a dome's .lp of six
    decimals, and the shipped .lp dome config using it (its camera made small)."""
    dirs = rig_geometry(load_rig_config(CONFIGS / "simulated_dome.toml")).directions
    lines = [f"{len(dirs)}"] + [
        f"led_{i + 1:02d}.jpg {x:.6f} {y:.6f} {z:.6f}" for i, (x, y, z) in enumerate(dirs)
    ]
    (tmp_path / "dome.lp").write_text("\n".join(lines) + "\n")
    text = (CONFIGS / "emulated_dome.toml").read_text()
    for old, new in (
        ('lp_file = "example_dome_48.lp"', 'lp_file = "dome.lp"'),
        ("width = 256", "width = 48"),
        ("height = 256", "height = 48"),
    ):
        assert old in text
        text = text.replace(old, new)
    cfg = tmp_path / "dome.toml"
    cfg.write_text(text)
    return cfg


@pytest.mark.parametrize(
    ("band", "edge", "on_edge"), [("--min-elevation-deg", 10, 12), ("--max-elevation-deg", 70, 6)]
)
def test_a_run_in_a_band_keeps_the_ring_on_its_edge(
    tmp_path: Path, band: str, edge: int, on_edge: int
) -> None:
    from rti_rig.cli import app

    cfg = _ring_dome(tmp_path)
    out = tmp_path / "s"
    args = ["run", str(cfg), band, str(edge), "--out", str(out), "--no-verdict"]
    r = CliRunner().invoke(app, args, terminal_width=400)
    assert r.exit_code == 0, r.output
    assert "48 lights" in r.output, r.output
    el = az_el_from_direction(np.array([e.direction for e in read_lp(out / "lights.lp")]))[1]
    assert int(np.sum(np.abs(el - edge) < 0.01)) == on_edge, el


def test_an_even_plan_from_a_floor_starts_on_the_floor_ring(tmp_path: Path) -> None:
    from rti_rig.cli import app

    _ring_dome(tmp_path)
    plan = tmp_path / "plan.lp"
    args = ["plan", "--rig", str(tmp_path / "dome.lp"), "--lights", "12", "--method", "uniform"]
    args += ["--min-elevation-deg", "10", "--out", str(plan)]
    r = CliRunner().invoke(app, args, terminal_width=400)
    assert r.exit_code == 0, r.output
    el = az_el_from_direction(np.array([e.direction for e in read_lp(plan)]))[1]
    assert np.min(el) == pytest.approx(10.0, abs=0.01), el  # it had begun at 25°
