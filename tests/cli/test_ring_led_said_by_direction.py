"""A ring dome's LED is said by its number and direction, never by the id its plans keep.

Why: a run stopped at a ring dome's dead LED advised "A resume lights LED 2 (led_002) first":
``led_002`` is the dome's machine-readable name for the LED (kept in plans and manifests), which
tells the user nothing about which LED to look at. The house style, as the preview's note and a
refused step say it, is "LED 2 (az 60.0°, el 10.0°)".
"""

from __future__ import annotations

import re
from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner(env={"COLUMNS": "400"})


def _ring_dome(tmp_path: Path, dead: int) -> Path:
    """The shipped emulated dome with the simulated dome's rings in place of its ``.lp``."""
    rings = re.search(
        r"(?ms)^\[dome\]\n.*?(?=^\[camera\])", (CONFIGS / "simulated_dome.toml").read_text()
    )
    assert rings is not None and 'layout = "rings"' in rings.group(0)
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = re.sub(
        r'(?m)^\[dome\]\nlayout = "lp"\nlp_file = "example_dome_48.lp"\n\n', rings.group(0), text
    )
    assert 'layout = "rings"' in text
    text = text.replace("width = 256", "width = 48").replace("height = 256", "height = 48")
    cfg = tmp_path / "ring dome.toml"
    cfg.write_text(text + f"\n[emulator]\ndead_leds = [{dead}]\n", encoding="utf-8")
    return cfg


def test_a_stop_at_a_ring_dome_s_dead_led_names_it_by_its_direction(tmp_path: Path) -> None:
    cfg = _ring_dome(tmp_path, dead=2)  # the lowest ring's third LED: 2 × 30° from +x
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--no-verdict"])
    text = said(r)
    assert r.exit_code == 2 and "LED 2 (az 60.0°, el 10.0°) refused" in text, text
    assert "A resume lights LED 2 (az 60.0°, el 10.0°) first and stops there again" in text, text
    assert "led_0" not in text, text
