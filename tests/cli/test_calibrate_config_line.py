"""`calibrate-lights` says to replace the correction a rig config already names, not to add a
second line.

Why: it said "To use it, add under [dome.serial] in RIG: intensity_correction_file = ..." to a
config that already had that key; done as told, the config is refused as invalid TOML
("Cannot overwrite a value"), and every command on that rig with it.
"""

from __future__ import annotations

from pathlib import Path

from card_support import card_rig, shoot
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_the_line_replaces_the_correction_the_config_names(tmp_path: Path) -> None:
    card = str(tmp_path / "card")
    plain = card_rig(tmp_path)
    shoot(plain, tmp_path / "card")
    first = ["calibrate-lights", card, "--rig", str(plain), "--out", str(tmp_path / "a.toml")]
    r = runner.invoke(app, first)
    assert r.exit_code == 0, r.output
    assert "To use it, add under [dome.serial] in" in said(r)
    corrected = card_rig(tmp_path, 'intensity_correction_file = "a.toml"\n', "cal.toml")

    again = ["calibrate-lights", card, "--rig", str(corrected), "--out", str(tmp_path / "b.toml")]
    r = runner.invoke(app, again)

    assert r.exit_code == 0, r.output
    assert "replace its intensity_correction_file line under [dome.serial] in" in said(r)
    assert "add under" not in said(r)
