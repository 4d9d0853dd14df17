"""``[emulator] led_power`` on a rig that is not emulated is refused with what becomes of a real
dome's uneven LEDs on *this* link.

Found by a review: the refusal said "the real driver applies the intensity correction that
evens them out" for every dome, untrue for the on/off firmwares (nab-rti-v1, rtipy, minirti,
elexol, rti-dome-m, nichlock, framed without levels), which cannot dim: their LEDs'
unevenness stays in the images.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _hardware_with_led_power(tmp_path: Path, shipped: str) -> Path:
    """A shipped emulated dome turned into a real (hardware) one, with an emulator LED spread."""
    text = (CONFIGS / shipped).read_text(encoding="utf-8")
    assert 'backend = "emulated"' in text and 'port = "emulated"' in text
    text = text.replace('backend = "emulated"', 'backend = "hardware"')
    text = text.replace('port = "emulated"', 'port = "/dev/ttyUSB7"')
    return write_config(tmp_path, text + "\n[emulator]\nled_power_spread = 0.2\n")


@pytest.mark.parametrize(
    "shipped", ["emulated_nab_rti_v1.toml", "emulated_rtipy.toml", "emulated_elexol.toml"]
)
def test_on_off_firmware_keeps_its_unevenness(tmp_path: Path, shipped: str) -> None:
    r = runner.invoke(app, ["check", str(_hardware_with_led_power(tmp_path, shipped))])
    out = " ".join(r.output.split())
    assert r.exit_code == 2, out
    assert "emulator.led_power" in out and "backend = 'emulated'" in out
    assert "evens them out" not in out
    assert "firmware cannot dim an LED" in out
    assert "unevenness stays in the images" in out
    assert "apply_light_gains" in out


def test_dimming_link_is_evened_out_by_the_driver(tmp_path: Path) -> None:
    r = runner.invoke(app, ["check", str(_hardware_with_led_power(tmp_path, "emulated_dome.toml"))])
    out = " ".join(r.output.split())
    assert r.exit_code == 2, out
    assert "the real driver applies the intensity correction that evens them out" in out
    assert "cannot dim" not in out
