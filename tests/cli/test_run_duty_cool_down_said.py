"""A run on a dome with a duty limit says how long its LEDs waited dark to cool.

The thermal guard (``[dome.serial.thermal] max_duty`` over ``duty_window_s``) makes an LED lit
again too soon wait before it lights: it does not over-drive it. But the wait was said only in
a debug log: metering that lights the same LEDs again and again on a duty-limited dome spent
most of the session cooling them (237.6 s of 256 s on the emulated dome below), with the rig
standing still and no word of why. The emulated dome with its real driver, through ``run``."""

from __future__ import annotations

import re
from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

THERMAL = """
[dome.serial.thermal]
max_on_s = 3.0
max_duty = 0.06
duty_window_s = 60.0
"""


def _duty_limited_dome(folder: Path) -> Path:
    """emulated_dome.toml with a 0.6 s exposure and a tight duty limit: an LED shot once
    (about 1.7 s lit) must cool before it lights again within the minute."""
    text = (CONFIGS / "emulated_dome.toml").read_text(encoding="utf-8")
    lp = 'lp_file = "example_dome_48.lp"'
    assert lp in text and "exposure_s = 0.05" in text
    text = text.replace(lp, f'lp_file = "{(CONFIGS / "example_dome_48.lp").as_posix()}"')
    config = folder / "rig.toml"
    config.write_text(text.replace("exposure_s = 0.05", "exposure_s = 0.6") + THERMAL)
    return config


def test_a_metered_run_on_a_duty_limited_dome_says_its_leds_waited_to_cool(
    tmp_path: Path,
) -> None:
    config = _duty_limited_dome(tmp_path)
    out = tmp_path / "s"
    argv = ["run", str(config), "--lights", "6", "--out", str(out), "--auto-exposure"]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0, text
    waited = re.search(r"LEDs waited dark (\d+\.\d) s to cool", text)
    assert waited, text
    total = re.search(r"Session time on the real rig: (\d+\.\d) s", text)
    assert total, text
    # metering lit its LEDs again within the minute: the guard made them wait, and that wait
    # is part of the rig's time (never more than it)
    assert 0.0 < float(waited.group(1)) <= float(total.group(1)), text
    assert "[dome.serial.thermal] max_duty = 0.06 over duty_window_s = 60 s" in text, text
    assert "All-off sent and acknowledged by the dome: lights are off." in text, text
    assert "Traceback" not in text, text


def test_a_run_whose_leds_never_waited_says_nothing_of_cooling(tmp_path: Path) -> None:
    """The shipped dome's default limit (50 % over a minute) never holds a short run back:
    no cooling is claimed where none was waited."""
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0, text
    assert "Session time on the real rig" in text, text
    assert "to cool" not in text, text
