"""`rti-rig check` on a firmware that reports no LED count says whose count it walked.

None of the real firmwares' profiles (the Nab sketch, RTIPy, minirti, Elexol, RTI_Dome,
nichlock) tells the host how many LEDs it has. The check's heading had said "elexol-24r1, 12
LEDs", as the heading of a firmware that reports its count does: read as established by the
board, though the 12 was the rig config's ``[dome.serial.protocol] led_count``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, emulated_dome_as_hardware
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.dome_link import DomeInfo
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

runner = CliRunner()


def test_check_says_the_led_count_is_the_configs_not_the_boards() -> None:
    r = runner.invoke(app, ["check", str(CONFIGS / "emulated_elexol.toml")], terminal_width=400)
    text = " ".join(r.output.split())
    assert r.exit_code == 0, text
    assert (
        "elexol-24r1, 12 LEDs per the rig config (dome.serial.protocol.led_count); this "
        "firmware does not report its count" in text
    ), text


def test_the_count_source_names_the_key_the_map_or_the_profile() -> None:
    def source(**serial: object) -> str:
        return DomeSerialSettings.model_validate(
            {"port": "/dev/null", "profile": "nab-rti-v1", **serial}
        ).led_count_source()

    assert source(protocol={"led_count": 12}) == ("the rig config (dome.serial.protocol.led_count)")
    assert source() == (
        "the nab-rti-v1 profile's own count (no led_count in [dome.serial.protocol])"
    )


def test_a_firmware_that_reports_its_count_keeps_a_bare_heading() -> None:
    assert DomeInfo("rti-rig-dome", "1.2", 48).led_count_heading() == "48 LEDs"
    said = DomeInfo("minirti", "", 12, "the rig config (x)").led_count_heading()
    assert said == "12 LEDs per the rig config (x); this firmware does not report its count"


@pytest.mark.pty
def test_a_hardware_dome_is_named_with_the_port_it_opened(tmp_path: Path) -> None:
    """A real dome's check said "dome: elexol-24r1, 12 LEDs" and, when it failed, "ABORTED:
    dome during 'handshake': … check the port": which port was opened was said nowhere (the
    emulated configs' "dome on /tmp/…" had it), so a user with two boards plugged in could not
    tell a wrong port from a silent board."""
    board = board_for("elexol-24r1")
    with serve_on_pty(board, "elexol-24r1") as link:
        cfg = emulated_dome_as_hardware(tmp_path, "emulated_elexol.toml", link.port)
        r = runner.invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert f"dome on {link.port}: elexol-24r1, 12 LEDs per the rig config" in said, said
