"""Files a command must not replace, even with --force (rti_rig/app/output_files.py), through
the CLI."""

from __future__ import annotations

import shutil
from pathlib import Path

from card_support import card_rig, said, shoot
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_calibrate_lights_refuses_to_replace_the_rigs_led_lp_even_with_force(
    tmp_path: Path,
) -> None:
    """`calibrate-lights --out DOME.lp --force` had written the light calibration's TOML over
    the dome's own LED calibration .lp (an input of the very command), after which every
    command on that rig was refused at load."""
    lp = tmp_path / "dome.lp"
    shutil.copyfile(CONFIGS / "example_dome_48.lp", lp)
    cfg = card_rig(tmp_path)
    cfg.write_text(cfg.read_text().replace(f"{CONFIGS}/example_dome_48.lp", "dome.lp"))
    before = lp.read_bytes()
    shoot(cfg, tmp_path / "card")

    card = str(tmp_path / "card")
    r = runner.invoke(
        app, ["calibrate-lights", card, "--rig", str(cfg), "--out", str(lp), "--force"]
    )

    assert r.exit_code == 2, r.output
    assert "dome.lp is the rig's LED calibration (lp_file) this command reads" in said(r)
    assert lp.read_bytes() == before
