"""`calibrate-lights` names the step of a card session that records no light.

Why: the card is read at the directions its steps recorded; a manifest whose step lacked one
(edited or damaged outside rti-rig) was refused as "does not describe a card session rti-rig
can read (KeyError: 'actual_direction')", naming neither the step nor its image nor a way out.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from card_support import card_rig, shoot
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize("light", [None, "up"], ids=["missing", "not-a-direction"])
def test_a_step_without_its_light_is_named_with_what_to_do(
    tmp_path: Path, light: str | None
) -> None:
    rig = card_rig(tmp_path)
    card = tmp_path / "card"
    shoot(rig, card)
    manifest = json.loads((card / "manifest.json").read_text())
    step = manifest["steps"][3]
    if light is None:
        del step["actual_direction"]
    else:
        step["actual_direction"] = light
    (card / "manifest.json").write_text(json.dumps(manifest))
    out = tmp_path / "cal.toml"

    r = runner.invoke(app, ["calibrate-lights", str(card), "--rig", str(rig), "--out", str(out)])

    assert r.exit_code == 2, r.output
    message = said(r)
    assert "Traceback" not in r.output
    assert "KeyError" not in message, message
    assert f"manifest.json: step 4 ({step['image']}, LED {step['led']})" in message, message
    what = "no light" if light is None else "'up', not a direction"
    assert what in message, message
    assert "restore manifest.json from a backup copy" in message, message
    assert not out.exists()
