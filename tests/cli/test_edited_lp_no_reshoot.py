"""A verdict that finds lights.lp edited since capture offers its mend, not a reshoot.

Found by a sweep: one line of a 48-light session's lights.lp turned 10° in azimuth; the verdict
said "lights.lp wrong: … write it again from the journal …: rti-rig export-lp S --out
S/lights.lp" and then "to reshoot image_020 in place, once what made the light wrong is mended
(an LED that did not fire …)", though image_020 is as captured and its journaled light right.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def _turned(lp: Path, name: str, deg: float) -> None:
    lines = lp.read_text().splitlines()
    for k, line in enumerate(lines):
        if line.startswith(name):
            word, *xyz = line.split()
            x, y, z = map(float, xyz)
            c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
            lines[k] = f"{word} {c * x - s * y:.6f} {s * x + c * y:.6f} {z:.6f}"
    lp.write_text("\n".join(lines) + "\n")


def test_an_edited_line_gets_the_lp_mend_and_no_reshoot(tmp_path: Path) -> None:
    s = tmp_path / "s"
    config = str(REPO / "rig_configs" / "simulated_dome.toml")
    r = runner.invoke(app, ["run", config, "--out", str(s), "--no-verdict"])
    assert r.exit_code == 0, r.output
    _turned(s / "lights.lp", "image_020", 10.0)
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "f")], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "QA verdict: lights.lp wrong: lights.lp gives image_020 another light" in said, said
    mend = f"rti-rig export-lp {s} --out {s / 'lights.lp'}"
    assert mend in said, said
    assert "--reshoot" not in said and "to reshoot" not in said, said
    # the mend, as printed, and the fit again: good
    r = runner.invoke(app, mend.split()[1:])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "f2")], terminal_width=400)
    assert r.exit_code == 0 and "QA verdict: good" in " ".join(r.output.split()), r.output
