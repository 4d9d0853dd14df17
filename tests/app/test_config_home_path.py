"""``dome.lp_file = "~/…"`` names the user's home, as the camera's ``folder`` does: it had been
looked for as a folder named ``~`` beside the config ("file …/~/dome.lp does not exist")."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS

from rti_rig.app.config import load_rig_config, rig_geometry


def test_a_dome_lp_under_home_is_found(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    home = tmp_path / "home"
    home.mkdir()
    shutil.copy(CONFIGS / "example_dome_48.lp", home / "dome.lp")
    text = (CONFIGS / "example_dome_48.toml").read_text()
    assert 'lp_file = "example_dome_48.lp"' in text
    cfg = tmp_path / "elsewhere" / "rig.toml"
    cfg.parent.mkdir()
    cfg.write_text(text.replace('lp_file = "example_dome_48.lp"', 'lp_file = "~/dome.lp"'))
    monkeypatch.setenv("HOME", str(home))

    loaded = load_rig_config(cfg)

    assert loaded.config.dome is not None and loaded.config.dome.lp_file == str(home / "dome.lp")
    assert len(rig_geometry(loaded).directions) == 48
