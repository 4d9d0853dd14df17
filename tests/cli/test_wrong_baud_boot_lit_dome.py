"""A Nab board at a wrong baud rate is switched off at its firmware's published rate.

The Nab sketch lights every LED in ``setup()``, and its Uno-class board resets when the port
opens. At a wrong ``baudrate`` (115200 left from the example config) nothing the host sends
reaches the sketch, and the all-off after the failed connect is garbage to it: the board was
left lit whole, the user told to switch it off at its supply. The port is now reopened at the
firmware's published rate (9600; the board resets again, lit while it boots) and its all-off
sent there: the report says it was acknowledged and that the board talks at 9600. A board that
answers at neither rate (a sketch changed to another rate) is still said to be lit whole. The
emulator's record is the truth.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.compose as compose
import rti_rig.app.usecases.check as check_usecase
from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.slow,  # the emulated board boots and is waited for in real time
    pytest.mark.pty,
]


def _check(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, board_baud: int) -> tuple:  # type: ignore[type-arg]
    boards: list = []  # type: ignore[type-arg]
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        rig.emulator.baudrate = board_baud  # the rate the sketch was built with
        boards.append(rig.emulator)
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    monkeypatch.setattr(check_usecase, "build_rig", build)
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        text.replace('profile = "nab-rti-v1"', 'profile = "nab-rti-v1"\nbaudrate = 115200')
    )
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    (board,) = boards
    return r.exit_code, " ".join(r.output.split()), board


def test_a_nab_board_at_a_wrong_baud_rate_is_switched_off_at_its_published_rate(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    code, said, board = _check(tmp_path, monkeypatch, 9600)
    assert code == 1, said
    assert "reopened at 9600 baud, the nab-rti-v1 firmware's published rate" in said, said
    assert "its all-off sent there was acknowledged: lights are off" in said
    assert "the board acknowledged its all-off there: it talks at 9600 baud" in said
    assert "power supply" not in said
    # the truth: booted twice (lit whole each time), and dark at the end
    assert [what for _, what in board.events].count("boot") == 2
    assert board.lit_once_booted() == frozenset()


def test_a_board_silent_at_both_rates_is_still_said_to_be_lit_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    code, said, board = _check(tmp_path, monkeypatch, 19200)
    assert code == 1, said
    assert "reopened at 9600 baud" in said and "was not acknowledged either" in said, said
    assert "every LED is on now; switch the dome off at its power supply" in said
    assert "it talks at 9600" not in said
    assert len(board.lit) > 1  # the truth: the board is lit whole


def test_a_port_silent_at_the_wrong_rate_is_not_reopened_at_the_published_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The wrong port and the wrong rate: nothing at all answers on the port (no board prints
    a banner, garbled or not). It is not reopened at 9600 for a second boot wait and reply
    timeout (7 s more with the Nab profile) for an all-off nothing receives; the lights line
    says why, and still says what a lit Nab board would need."""
    import os
    import tty

    from conftest import emulated_dome_as_hardware

    from rti_rig.drivers.led_dome.transport import SerialTransport

    master, slave = os.openpty()  # a port with nothing behind it: it reads what it is sent
    tty.setraw(slave)
    port = os.ttyname(slave)
    os.close(slave)
    opened_at: list[int] = []
    real_open = SerialTransport.open

    def counted(self):  # type: ignore[no-untyped-def]
        opened_at.append(self.baudrate)
        real_open(self)

    monkeypatch.setattr(SerialTransport, "open", counted)
    cfg = emulated_dome_as_hardware(tmp_path, "emulated_nab_rti_v1.toml", port)
    text = cfg.read_text().replace("reply_timeout_s = 3.0", "reply_timeout_s = 0.5")
    text = text.replace('profile = "nab-rti-v1"', 'profile = "nab-rti-v1"\nbaudrate = 115200')
    cfg.write_text(text.replace("led_count = 12", "led_count = 12\nboot_wait_s = 0.5"))
    try:
        r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    finally:
        os.close(master)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert opened_at == [115200], opened_at  # once, at the configured rate
    assert "not reopened at 9600 baud" in said and "not one byte came from the port" in said
    # the lights line and the connect's advice agree: a slow bootloader is silent too
    assert "a board slower to boot than boot_wait_s (see the connect's advice)" in said, said
    assert "if the board is slow to boot, raise boot_wait_s" in said, said
    assert "switch the dome off at its power supply" in said, said
