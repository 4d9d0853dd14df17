"""A lamp distance the simulated relief cannot render is refused, not silently dropped.

`[scene] light_distance_mm = 100` on the relief (the shipped simulated dome's scene) ran and said
nothing: the relief is rendered under directional lights only, so the session claimed point
lamps 100 mm away and rendered lights at infinity.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.errors import ConfigError

runner = CliRunner()


def test_the_relief_with_a_lamp_distance_is_refused_naming_the_key(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME + "light_distance_mm = 100.0\n")
    with pytest.raises(ConfigError) as err:
        load_rig_config(cfg)
    text = str(err.value)
    assert "rig.toml" in text and "scene" in text and "light_distance_mm" in text, text
    assert "directional lights only" in text and "coin" in text, text
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "3"])
    assert r.exit_code == 2 and "light_distance_mm has no effect on the relief" in r.output
    assert not (tmp_path / "s").exists()


def test_a_library_scene_keeps_its_lamp_distance(tmp_path: Path) -> None:
    text = SMALL_DOME.replace("seed = 3", 'seed = 3\nname = "tablet"\nlight_distance_mm = 100.0')
    loaded = load_rig_config(write_config(tmp_path, text))
    assert loaded.config.scene.light_distance_mm == 100.0
