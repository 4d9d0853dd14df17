"""`rti-rig plan` on a dome of fewer LEDs than its default 12 says the 12 is the default.

Why: on the shipped 8-LED configs (emulated_rtipy.toml, emulated_rti_dome.toml) a plan with no
--lights was refused as "asked for 12 lights but the dome has only 8 LEDs", though the user
had asked for no number.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize("config", ["emulated_rtipy.toml", "emulated_rti_dome.toml"])
def test_the_default_number_of_lights_is_said_as_the_default(tmp_path: Path, config: str) -> None:
    out = tmp_path / "plan.lp"

    r = runner.invoke(app, ["plan", "--rig", str(CONFIGS / config), "--out", str(out)])

    assert r.exit_code == 2, r.output
    text = said(r)
    assert "asked for" not in text, text
    assert (
        "the dome has 8 LEDs, fewer than the 12 lights plan plans when --lights is not given"
        in (text)
    ), text
    assert "give --lights 8 or fewer" in text, text
    assert not out.exists()
    r = runner.invoke(
        app, ["plan", "--rig", str(CONFIGS / config), "--out", str(out), "--lights", "8"]
    )
    assert r.exit_code == 0, r.output


def test_lights_asked_for_are_still_said_asked_for(tmp_path: Path) -> None:
    rig = CONFIGS / "emulated_rtipy.toml"
    r = runner.invoke(
        app, ["plan", "--rig", str(rig), "--out", str(tmp_path / "p.lp"), "--lights", "12"]
    )
    assert r.exit_code == 2, r.output
    assert "asked for 12 lights but the dome has only 8 LEDs" in said(r), said(r)
