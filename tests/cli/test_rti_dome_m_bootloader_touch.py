"""rti-dome-m runs on an ATmega32u4, whose port reaches the sketch at any baud rate except one:
opening it at 1200 baud and closing it is the Arduino "1200-baud touch", which drops the board
into its bootloader (the sketch stopped for 8 s, then restarted). The config had been accepted
with ``baudrate = 1200``; a check then opened the port at that rate, and every close reset the
dome. Refused as the config loads, before any port opens, naming the key and what to do.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, emulators_built_by_check, said, write_config
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.drivers.led_dome.transport import SerialTransport

runner = CliRunner()
SHIPPED = "emulated_rti_dome.toml"


def variant(tmp_path: Path, old: str, new: str) -> Path:
    text = (CONFIGS / SHIPPED).read_text(encoding="utf-8")
    assert old in text, old
    return write_config(tmp_path, text.replace(old, new, 1))


def opened_ports(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The serial transports opened from here on."""
    opened: list[Any] = []
    real_open = SerialTransport.open

    def record(self: SerialTransport) -> None:
        opened.append(self)
        real_open(self)

    monkeypatch.setattr(SerialTransport, "open", record)
    return opened


@pytest.mark.parametrize(
    ("old", "new", "key"),
    [
        ("retries = 2", "retries = 2\nbaudrate = 1200", "dome.serial.baudrate"),
        (
            "[dome.serial.protocol]\n",
            "[dome.serial.protocol]\nbaudrate = 1200\n",
            "dome.serial.protocol.baudrate",
        ),
    ],
    ids=["serial", "protocol"],
)
@pytest.mark.parametrize("command", [["check"], ["run", "--lights", "4"]], ids=["check", "run"])
def test_1200_baud_on_the_32u4_dome_is_refused_before_any_port_opens(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    old: str,
    new: str,
    key: str,
    command: list[str],
) -> None:
    cfg = variant(tmp_path, old, new)
    built = emulators_built_by_check(monkeypatch)
    opened = opened_ports(monkeypatch)
    args = [command[0], str(cfg), *command[1:]]
    if command[0] == "run":
        args += ["--out", str(tmp_path / "session")]
    r = runner.invoke(app, args)
    text = said(r)
    assert r.exit_code == 2, text
    assert f"{key} = 1200 is the rate at which the rti-dome-m firmware's board" in text
    assert "jumps to its bootloader when the port closes (the Arduino 1200-baud touch)" in text
    assert f"remove {key} (the firmware's own 9600 is used) or set another rate" in text
    assert "Traceback" not in text
    assert built == [] and opened == []
    assert not (tmp_path / "session").exists()


@pytest.mark.parametrize("baud", [9600, 115200, 300])
def test_any_other_rate_loads_for_the_32u4_dome(tmp_path: Path, baud: int) -> None:
    cfg = variant(tmp_path, "retries = 2", f"retries = 2\nbaudrate = {baud}")
    assert load_rig_config(cfg).config.dome.serial.baudrate == baud  # type: ignore[union-attr]


def test_1200_baud_is_not_refused_for_a_board_behind_a_uart(tmp_path: Path) -> None:
    """Only the 32u4's own USB resets at 1200: a nab-rti-v1 Uno talks through its USB-serial
    chip, where 1200 is just a (wrong) rate, said as such when the board answers nothing."""
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text(encoding="utf-8")
    cfg = write_config(tmp_path, text.replace("retries = 2", "retries = 2\nbaudrate = 1200", 1))
    assert load_rig_config(cfg).config.dome.serial.baudrate == 1200  # type: ignore[union-attr]
