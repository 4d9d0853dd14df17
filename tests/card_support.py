"""Shared by the light-calibration tests: a card rig (the shipped emulated dome with uneven LEDs)
and a session shot on it through the CLI."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()

#: Each emulated LED's true output: 48 LEDs, 0.6–1.4 of nominal, fixed for the test.
TRUE_POWER = np.round(np.exp(0.2 * np.random.default_rng(7).standard_normal(48)), 3).clip(0.6, 1.4)


def card_rig(tmp_path: Path, serial_extra: str = "", name: str = "card.toml") -> Path:
    """The shipped emulated dome, small frames, shooting the matte plate, with uneven LEDs."""
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace("width = 256", "width = 48").replace("height = 256", "height = 48")
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    text = re.sub(r'(?m)^name = "tablet"', 'name = "flat"', text)
    assert 'name = "flat"' in text
    text = text.replace('profile = "default"\n', f'profile = "default"\n{serial_extra}')
    power = ", ".join(f"{p:g}" for p in TRUE_POWER)
    return write_config(tmp_path, text + f"\n[emulator]\nled_power = [{power}]\n", name)


def shoot(cfg: Path, out: Path) -> None:
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out)])
    assert r.exit_code == 0, r.output
