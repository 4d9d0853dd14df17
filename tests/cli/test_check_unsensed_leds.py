"""``rti-rig check`` of a dome whose firmware senses no LED current says what it established.

The Nab sketch (and every described firmware) acknowledges a light command whether the LED
lit or not. Its check had said "passed: 12 … RESULT: PASS" of a dome with a dead LED: only
the board's acknowledgement was established. The emulated board here has LED 3 dead
(``[emulator] dead_leds``): it acknowledges it as the real board would, and gives no light.
"""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
from conftest import CONFIGS, at_key, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _nab(tmp_path: Path, dead: str) -> Path:
    cfg = tmp_path / "nab.toml"
    cfg.write_text(
        (CONFIGS / "emulated_nab_rti_v1.toml").read_text() + f"\n[emulator]\ndead_leds = {dead}\n"
    )
    return cfg


@pytest.mark.pty
def test_a_check_of_a_board_that_senses_no_current_claims_no_led_lit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "led-check").mkdir()  # taken: the advice names the next free folder
    r = runner.invoke(app, ["check", str(_nab(tmp_path, "[3]"))], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0 and "Traceback" not in text, text
    assert "LEDs stepped: 12, acknowledged by the board: 12, failed: 0" in text, text
    assert "passed: 12" not in text, text
    assert "whether each LED lights cannot be sensed by this firmware" in text, text
    # the session and its fit as commands that run pasted: the config checked and free
    # folders (it had said `rti-rig fit S --out FOLDER`, which pasted made folders S, FOLDER)
    cfg = shlex.quote(str(tmp_path / "nab.toml"))
    assert f"(`rti-rig run {cfg} --out led-check-2`)" in text, text
    fit = "`rti-rig fit led-check-2 --out led-check-2-fit --no-ptm --no-hsh --no-normals`"
    assert fit in text, text
    assert r.output.rstrip().splitlines()[-1] == (
        "RESULT: PASS (LEDs acknowledged; lit not verified: board cannot sense current)"
    )


@pytest.mark.parametrize("dead", ["[12]", "[-1, 3]"])
def test_a_dead_led_the_dome_has_not_is_refused_by_name(tmp_path: Path, dead: str) -> None:
    """An index outside the dome's LEDs had been ignored without a word: the rehearsal had no
    dead LED at all."""
    cfg = _nab(tmp_path, dead)
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, text
    assert f"{at_key(cfg, 'emulator.dead_leds')}" in text, text
    assert "not among this dome's 12 LEDs: give LED indices from 0 to 11" in text, text
    assert "LEDs stepped" not in text, text  # refused before the port opened


def _own_firmware_dome(tmp_path: Path, serial_extra: str) -> Path:
    """The shipped emulated dome (this project's `default` protocol) whose board measures no
    LED current and has LED 3 dead: it acknowledges LED 3 and gives no light."""
    text = (CONFIGS / "emulated_dome.toml").read_text()
    text = text.replace(
        'lp_file = "example_dome_48.lp"', f'lp_file = "{CONFIGS}/example_dome_48.lp"'
    )
    text = text.replace('profile = "default"\n', f'profile = "default"\n{serial_extra}')
    cfg = tmp_path / "own.toml"
    cfg.write_text(text + "\n[emulator]\ndead_leds = [3]\nreports_dead_leds = false\n")
    return cfg


@pytest.mark.pty
def test_an_own_firmware_board_without_current_sensing_is_checked_for_what_it_established(
    tmp_path: Path,
) -> None:
    """Its check had said "passed: 48 … RESULT: PASS" with LED 3 dead. The protocol cannot
    tell whether the board senses current: the config says so (``senses_led_current``), and
    a rehearsal of such a board that does not say it is refused by key before the port opens."""
    cfg = _own_firmware_dome(tmp_path, "")
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, text
    assert f"{at_key(cfg, 'emulator.reports_dead_leds')}" in text, text
    assert "set senses_led_current = false under [dome.serial]" in text, text
    assert "LEDs stepped" not in text and "passed:" not in text, text

    cfg = _own_firmware_dome(tmp_path, "senses_led_current = false\n")
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0 and "Traceback" not in text, text
    assert "LEDs stepped: 48, acknowledged by the board: 48, failed: 0" in text, text
    assert "passed: 48" not in text, text
    assert r.output.rstrip().splitlines()[-1] == (
        "RESULT: PASS (LEDs acknowledged; lit not verified: board cannot sense current)"
    )


def test_senses_led_current_on_a_described_firmware_is_refused_by_key(tmp_path: Path) -> None:
    cfg = tmp_path / "nab.toml"
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    assert "[dome.serial]\n" in text
    cfg.write_text(text.replace("[dome.serial]\n", "[dome.serial]\nsenses_led_current = true\n"))
    r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, text
    assert "senses_led_current is for this project's own protocols" in text, text
