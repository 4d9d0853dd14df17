"""Shared fixtures: repository paths and small rigs built from the shipped configs."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
CONFIGS = REPO / "rig_configs"


@pytest.fixture
def dome_config_path() -> Path:
    return CONFIGS / "simulated_dome.toml"


@pytest.fixture
def arm_config_path() -> Path:
    return CONFIGS / "virtual_arm.toml"


def write_config(tmp_path: Path, text: str, name: str = "rig.toml") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


SMALL_DOME = """
name = "small"
kind = "dome"
backend = "simulated"
[dome]
layout = "rings"
rings = [
  { elevation_deg = 20.0, count = 8 },
  { elevation_deg = 50.0, count = 4, azimuth_offset_deg = 45.0 },
]
[camera]
width = 64
height = 64
exposure_s = 0.05
[scene]
seed = 3
"""
