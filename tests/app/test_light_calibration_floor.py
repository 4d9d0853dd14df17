"""`calibrate-lights --min-elevation-deg` above the card session's LEDs is refused by name
(rti_rig/app/light_calibration.py).

Why: the refusal had been the gain estimate's, "only 0 lights light the card at shading >=
0.966: need 4; is the card's normal right?", which sent the user to the card's normal when the
floor they had given was the cause.
"""

from __future__ import annotations

from pathlib import Path

from card_support import card_rig, shoot
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_a_floor_above_the_leds_names_the_option_not_the_card_normal(tmp_path: Path) -> None:
    cfg = card_rig(tmp_path)
    shoot(cfg, tmp_path / "card")
    out = str(tmp_path / "c.toml")

    card = str(tmp_path / "card")
    floor = ["--min-elevation-deg", "75"]
    r = runner.invoke(app, ["calibrate-lights", card, "--rig", str(cfg), "--out", out, *floor])

    assert r.exit_code == 2, r.output
    text = said(r)
    assert "only 0 of its 48 LEDs are at or above --min-elevation-deg 75 above the card" in text
    assert "lower --min-elevation-deg" in text
    assert "card's normal" not in text
    assert not Path(out).exists()
