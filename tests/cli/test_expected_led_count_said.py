"""A dome config whose ``expected_led_count`` disagrees with its ``.lp`` says where the other
count comes from and which to change; it had said "expected_led_count = 40 but 48 LEDs given",
given by what left unsaid."""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app


def test_an_expected_led_count_against_the_lp_names_both(tmp_path: Path) -> None:
    text = (CONFIGS / "emulated_dome.toml").read_text(encoding="utf-8")
    lp = (CONFIGS / "example_dome_48.lp").resolve().as_posix()
    text = text.replace('lp_file = "example_dome_48.lp"', f'lp_file = "{lp}"')
    text = text.replace("[dome.serial]\n", "[dome.serial]\nexpected_led_count = 40\n", 1)
    cfg = tmp_path / "dome.toml"
    cfg.write_text(text, encoding="utf-8")
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said, r.output
    assert "key 'dome.serial.expected_led_count'" in said, said
    assert f"expected_led_count = 40, but dome.lp_file ({lp}) lists 48 LEDs" in said, said
    assert "set expected_led_count = 48 if the dome has 48 LEDs" in said, said
