"""An adaptive session whose band leaves one ring of LEDs starts spread round it.

`run simulated_dome.toml --adaptive --lights 5 --min-elevation-deg 60` has the 70° ring's six
LEDs to choose from; its start had been the LEDs at 0°, 60°, 120° and 300° (the golden-angle
spiral of the homogeneous layouts, whose elevations cannot spread it on one ring): three on
one side, nothing within 180° of 210°.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, interrupted, journal, write_config
from typer.testing import CliRunner

import rti_rig.app.usecases.adaptive as usecase
from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.app.usecases.adaptive import dome_start
from rti_rig.cli import app
from rti_rig.core.rig_geometry import DomeGeometry

runner = CliRunner()


def largest_gap_deg(directions: list[list[float]]) -> float:
    """The widest azimuth interval (°) with no light in it."""
    az = sorted(math.degrees(math.atan2(d[1], d[0])) % 360.0 for d in directions)
    return max(np.diff([*az, az[0] + 360.0]))


def test_the_start_is_spread_round_the_one_ring_of_the_band(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(
        app,
        [
            "run",
            str(CONFIGS / "simulated_dome.toml"),
            "--out",
            str(out),
            "--adaptive",
            "--lights",
            "5",
            "--min-elevation-deg",
            "60",
            "--no-verdict",
        ],
    )
    assert r.exit_code == 0, r.output
    start = [s["actual_direction"] for s in journal(out) if s["decision"]["kind"] == "start"]
    assert len(start) == 4
    # four of the five LEDs of the design on a ring of six: 120° is the narrowest widest gap
    assert largest_gap_deg(start) == pytest.approx(120.0, abs=0.01)


@pytest.mark.parametrize("n_total", [None, 5, 6])
def test_every_start_on_one_ring_is_spread(n_total: int | None) -> None:
    """--until-error (N unknown) and --lights N alike."""
    geometry = rig_geometry(load_rig_config(CONFIGS / "simulated_dome.toml"))
    ring = np.flatnonzero(geometry.directions[:, 2] > math.sin(math.radians(60)))
    sub = DomeGeometry(geometry.directions[ring], tuple(geometry.names[i] for i in ring))
    start = dome_start(sub, 4, n_total, band=(60.0, 90.0))
    assert largest_gap_deg(sub.directions[start].tolist()) == pytest.approx(120.0, abs=0.01)


def test_a_session_begun_before_the_ring_start_resumes_as_it_began(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A new decision constant had refused the resume of every adaptive session begun before
    it ("RING_SPAN_DEG 'absent' → 2.0"); this one is restored from the session (absent: no
    ring start), so such a session resumes and keeps the start it began with."""
    text = (CONFIGS / "simulated_dome.toml").read_text()
    assert "width = 512\nheight = 512" in text
    cfg = write_config(
        tmp_path, text.replace("width = 512\nheight = 512", "width = 48\nheight = 48")
    )
    out = tmp_path / "s"
    began = usecase.dome_start
    # as a build before the rule began it: the golden-angle start, no constant recorded
    monkeypatch.setattr(
        usecase, "dome_start", lambda *a, **k: began(*a, **{**k, "ring_span_deg": None})
    )
    interrupted(cfg, out, after_step=1, lights=5, band=(60.0, 90.0))
    monkeypatch.undo()
    m = json.loads((out / "manifest.json").read_text())
    del m["adaptive"]["constants"]["app.usecases.adaptive.RING_SPAN_DEG"]
    (out / "manifest.json").write_text(json.dumps(m))
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    start = [s["actual_direction"] for s in journal(out) if s["decision"]["kind"] == "start"]
    assert largest_gap_deg(start) == pytest.approx(180.0, abs=0.01)  # as it began
