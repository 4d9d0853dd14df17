"""A light calibration that measured only some LEDs leaves the others uneven, and says so.

A card shot under 12 of the shipped card dome's 48 LEDs gives a correction that assumes the other
36 give the median light. The run that used it counted the dome as evened out: ``--auto-exposure``
metered at one light and 5 of the 48 images of the card clipped 67–100 % (image_037, 039, 040,
043, 048). Now metering checks the brightest planned lights as on an uncalibrated dome, with a
note naming the 12 of 48, and the QA verdict explains a bright image under an unmeasured LED as
its LED's own light (a reshoot repeats it), as it does on an uncalibrated dome.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.pty
def test_a_partial_calibration_is_metered_as_uneven_and_nothing_clips(tmp_path: Path) -> None:
    cfg = tmp_path / "card.toml"
    shutil.copy(CONFIGS / "emulated_dome_card.toml", cfg)
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    card = tmp_path / "card"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(card), "--lights", "12", "--no-verdict"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(cfg)])
    assert r.exit_code == 0, r.output
    assert "12 of 48 LEDs measured" in said(r)
    line = 'intensity_correction_file = "card/light_calibration.toml"'
    text = cfg.read_text()
    cfg.write_text(text.replace('profile = "default"\n', f'profile = "default"\n{line}\n', 1))

    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--auto-exposure"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "light calibration measured 12 of its 48 LEDs" in text
    assert "the brightest of the 6 metered" in text
    steps = json.loads((out / "manifest.json").read_text())["steps"]
    assert len(steps) == 48
    assert max(s["saturated_fraction"] for s in steps) <= 0.001
    assert "saturated" not in text.split("QA verdict:")[1]
    # a bright image under an LED the calibration did not measure is its LED's own light
    assert "no image to reshoot" in text and "LEDs the light calibration did not measure" in text
