"""`rti-rig calibrate-lights --rig` a rig that cannot dim LEDs says why, as it is.

Found by a front-door audit: an arm (`virtual_arm.toml`) and a camera-triggered dome
(`emulated_cceh_rti.toml`) were both told "has no [dome.serial]: only a serial dome can dim its
LEDs (the simulated backend's are exact)": neither is a simulated dome.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize(
    ("config", "said"),
    [
        ("virtual_arm.toml", "rig 'virtual-arm' is an arm: calibrate-lights evens out the LEDs"),
        (
            "emulated_cceh_rti.toml",
            "has no [dome.serial]: only a dome driven over a serial link can dim its LEDs",
        ),
        ("simulated_dome.toml", "has no [dome.serial]: a simulated dome's LEDs are exact"),
    ],
)
def test_the_refusal_says_why_this_rig_cannot_dim(tmp_path: Path, config: str, said: str) -> None:
    card = tmp_path / "card"
    card.mkdir()
    out = tmp_path / "calibration.toml"
    r = runner.invoke(
        app,
        ["calibrate-lights", str(card), "--rig", str(CONFIGS / config), "--out", str(out)],
    )
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert "Traceback" not in text
    assert said in text, text
    assert "simulated backend" not in text
    assert not out.exists()
