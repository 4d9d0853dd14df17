"""Files a command must not replace, even with --force (rti_rig/app/output_files.py), through
the CLI: the rig's own files are inputs of every command that loads the rig."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from card_support import card_rig, shoot
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def card(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """(rig config, its own LED .lp, a card session shot on it): the .lp a copy, so that a
    command that wrongly replaced it could not touch the repository's."""
    tmp = tmp_path_factory.mktemp("card")
    lp = tmp / "dome.lp"
    shutil.copyfile(CONFIGS / "example_dome_48.lp", lp)
    cfg = card_rig(tmp)
    cfg.write_text(cfg.read_text().replace(f"{CONFIGS}/example_dome_48.lp", "dome.lp"))
    shoot(cfg, tmp / "card")
    return cfg, lp, tmp / "card"


def test_calibrate_lights_refuses_to_replace_the_rigs_led_lp_even_with_force(
    card: tuple[Path, Path, Path],
) -> None:
    """`calibrate-lights --out DOME.lp --force` had written the light calibration's TOML over
    the dome's own LED calibration .lp (an input of the very command), after which every
    command on that rig was refused at load."""
    cfg, lp, session = card
    before = lp.read_bytes()

    r = runner.invoke(
        app, ["calibrate-lights", str(session), "--rig", str(cfg), "--out", str(lp), "--force"]
    )

    assert r.exit_code == 2, r.output
    assert "dome.lp is the rig's LED calibration (lp_file) this command reads" in said(r)
    assert lp.read_bytes() == before


def test_the_intensity_correction_in_force_is_not_replaced_by_plan_or_calibrate_lights(
    card: tuple[Path, Path, Path],
) -> None:
    """`plan --rig RIG --out CORRECTION --force` had written a plan over the rig's LED intensity
    correction file, after which the rig config was refused at load ("not valid TOML")."""
    cfg, _, session = card
    folder = cfg.parent
    correction = folder / "correction.toml"
    r = runner.invoke(
        app, ["calibrate-lights", str(session), "--rig", str(cfg), "--out", str(correction)]
    )
    assert r.exit_code == 0, r.output
    calibrated = card_rig(folder, 'intensity_correction_file = "correction.toml"\n', "cal.toml")
    calibrated.write_text(
        calibrated.read_text().replace(f"{CONFIGS}/example_dome_48.lp", "dome.lp")
    )
    before = correction.read_bytes()
    refusal = "correction.toml is the rig's LED intensity correction (intensity_correction_file)"

    r = runner.invoke(app, ["plan", "--rig", str(calibrated), "--out", str(correction), "--force"])
    assert r.exit_code == 2, r.output
    assert refusal in said(r)
    again = ["calibrate-lights", str(session), "--rig", str(calibrated), "--out", str(correction)]
    r = runner.invoke(app, [*again, "--force"])
    assert r.exit_code == 2, r.output
    assert refusal in said(r)
    assert correction.read_bytes() == before
