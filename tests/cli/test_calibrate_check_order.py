"""`calibrate-lights` names what no move of a file fixes before what one does.

Before: a card session calibrated already (its light_calibration.toml there) given another
rig's config was told "light_calibration.toml exists: … to write the calibration elsewhere:
rti-rig calibrate-lights … --out …"; run as told, it was only then refused as a card of
another rig. The card's rig is now compared first, from its manifest, as before any image is
read.
"""

from __future__ import annotations

import re
from pathlib import Path

from card_support import card_rig, shoot
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_another_rigs_card_is_refused_before_its_existing_calibration(tmp_path: Path) -> None:
    rig = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(rig, card)
    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(rig)])
    assert r.exit_code == 0, said(r)
    written = card / "light_calibration.toml"
    before = written.read_bytes()
    other = tmp_path / "other.toml"
    text = rig.read_text()
    other.write_text(re.sub(r'(?m)^name = "[^"]*"', 'name = "another-dome"', text, count=1))

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(other)])

    assert r.exit_code == 2, said(r)
    assert "was shot on rig" in said(r) and "not 'another-dome'" in said(r), said(r)
    assert "exists" not in said(r), said(r)  # not sent to write elsewhere first
    assert written.read_bytes() == before
    # the way on for a dome only renamed: its name given back (pasted, that config calibrates)
    old = re.search(r'(?m)^name = "[^"]*"', text)
    assert old is not None
    assert (
        f"if 'another-dome' is that same dome renamed, give its config's name back, {old[0]}"
        in (said(r))
    ), said(r)


def test_an_on_off_dome_given_another_domes_correction_is_told_to_remove_it(
    tmp_path: Path,
) -> None:
    """nab-rti-v1 cannot dim an LED. Given another dome's correction it had been told to
    "calibrate this dome (rti-rig calibrate-lights)", which refuses a dome that cannot dim."""
    from conftest import CONFIGS

    (tmp_path / "other_cal.toml").write_text(
        'format = "rti-rig-light-calibration/1"\nrig = "some-other-dome"\n'
        f"intensity_correction = [{', '.join(['1.0'] * 12)}]\n"
    )
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    old = 'profile = "nab-rti-v1"\n'
    assert text.count(old) == 1
    config = tmp_path / "nab.toml"
    config.write_text(text.replace(old, old + 'intensity_correction_file = "other_cal.toml"\n'))
    out = tmp_path / "s"

    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--no-verdict"])

    assert r.exit_code == 2, said(r)
    assert "key 'dome.serial.intensity_correction_file': the nab-rti-v1 firmware cannot dim" in (
        said(r)
    ), said(r)
    assert "Remove the key" in said(r) and "calibrate-lights" not in said(r), said(r)
    assert not out.exists()
