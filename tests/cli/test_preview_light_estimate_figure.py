"""The error `plan` quotes for a preview light estimated from shading is one it measures.

`plan` had quoted "17–59° on a real icon's previews" beside every estimated light, read as a
bound; on image05.jpg of the shipped real acquisition (its light recorded at 16° elevation)
the estimate is 106° off, and that figure is now quoted too. This checks it against the
acquisition's own `.lp`, through the CLI.
"""

from __future__ import annotations

import re
from pathlib import Path

from conftest import said
from typer.testing import CliRunner

from rti_rig.app.usecases.plan import ESTIMATE_OFF_GRAZING_DEG
from rti_rig.cli import app
from rti_rig.core.geometry import angle_between_deg, direction_from_az_el
from rti_rig.core.lp_format import read_lp

ACQ = Path(__file__).resolve().parent.parent / "data" / "neuralrti_replay"


def test_the_quoted_figure_is_the_estimate_error_on_the_shipped_image(tmp_path: Path) -> None:
    out = tmp_path / "p.lp"
    argv = ["plan", str(ACQ / "image05.jpg"), "--lights", "9", "--method", "optimal"]
    r = CliRunner().invoke(app, [*argv, "--out", str(out)], terminal_width=400)
    assert r.exit_code == 0, said(r)
    text = said(r)
    match = re.search(r"preview light az ([\d.]+)°, el ([\d.]+)° \(estimated", text)
    assert match, text
    estimated = direction_from_az_el(float(match[1]), float(match[2]))
    (recorded,) = [e.direction for e in read_lp(ACQ / "dirs.lp") if e.name == "image05.jpg"]
    off = float(angle_between_deg(estimated, recorded))
    assert round(off) == ESTIMATE_OFF_GRAZING_DEG, off
    assert f"{ESTIMATE_OFF_GRAZING_DEG}° on another real acquisition's image" in text
