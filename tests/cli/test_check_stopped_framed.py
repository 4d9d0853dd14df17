"""`rti-rig check` on the shipped framed-profile dome (``example_dome_48.toml``, its board
emulated on a pty) stopped by Ctrl-C while the dome connects: the all-off is sent once the
board has booted, and the line says what it established, as on the line-protocol firmwares.
A stop inside the port's opening is tested on the default profile too (the shipped
``emulated_dome.toml``): the same driver runs both profiles, and each is covered.

The framed profile's driver had been left out of that fix: a Ctrl-C inside the port's opening
(the system had opened it, which resets an Arduino-class board; pyserial closes it again as the
stop goes through) sent no all-off and said "the dome was never reached", and a Ctrl-C in the
boot wait sent the all-off at once, into the bootloader, where it is lost. The Ctrl-Cs are real
SIGINTs through the check's handler, raised at those points (no race)."""

from __future__ import annotations

import contextlib
import signal
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, emulators_built_by_check, shipped_dome_on_pty
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux"),
]

SHIPPED = CONFIGS / "example_dome_48.toml"
#: the shipped configs of each profile the dome driver (``LedDomeDriver``) runs: framed (a
#: hardware config, its board emulated here) and default (served by the dry run's emulator)
BY_PROFILE = {"framed": SHIPPED, "default": CONFIGS / "emulated_dome.toml"}


def _check_said(config: Path = SHIPPED) -> tuple[int, str]:
    r = CliRunner().invoke(app, ["check", str(config)], terminal_width=400)
    return r.exit_code, " ".join(r.output.split())


@contextlib.contextmanager
def _emulated_board(monkeypatch: pytest.MonkeyPatch, config: Path) -> Iterator[Callable[[], Any]]:
    """The emulated firmware behind ``config`` (called once the check has run): a hardware
    config's port redirected to one on a pty, or the dry run's own emulator."""
    if 'backend = "emulated"' in config.read_text():
        emulators = emulators_built_by_check(monkeypatch)
        yield lambda: emulators[-1]
        return
    with shipped_dome_on_pty(monkeypatch, config) as firmware:
        yield lambda: firmware


@pytest.mark.parametrize("profile", list(BY_PROFILE))
@pytest.mark.parametrize(
    ("sig", "code", "name"), [(signal.SIGINT, 130, "Ctrl-C"), (signal.SIGTERM, 143, "SIGTERM")]
)
def test_a_stop_inside_the_opening_of_the_dome_port_still_switches_the_board_off(
    monkeypatch: pytest.MonkeyPatch, sig: signal.Signals, code: int, name: str, profile: str
) -> None:
    import serial

    config = BY_PROFILE[profile]
    assert f'profile = "{profile}"' in config.read_text()
    with _emulated_board(monkeypatch, config) as board:
        redirected = serial.serial_for_url
        stops: list[int] = []

        def opened(*args, **kwargs):  # type: ignore[no-untyped-def]
            port = redirected(*args, **kwargs)
            if not stops:  # the user's one stop, in the first opening
                stops.append(sig)
                try:
                    signal.raise_signal(sig)
                except BaseException:
                    port.close()  # as pyserial's own open does when a stop goes through it
                    raise
            return port

        monkeypatch.setattr(serial, "serial_for_url", opened)
        exit_code, said = _check_said(config)
        firmware = board()
    assert stops and exit_code == code, said
    assert "Traceback" not in said
    assert "never reached" not in said, said
    assert f"Check stopped ({name}): all-off sent and acknowledged by the dome" in said, said
    events = [e.what for e in firmware.history]
    assert events.count("boot") == 2, events  # the opening reset it, and so did the reopening
    assert firmware.commands_received >= 1 and "lost while booting" not in events, events
    assert firmware.lit is None


def test_a_ctrl_c_in_the_framed_boards_boot_wait_switches_it_off_once_it_has_booted(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The board spends 1 s in its bootloader after the opening's reset (within the config's
    ready_timeout_s = 3 s), where bytes sent are lost: the all-off waits for its banner. A second
    Ctrl-C during that wait is held until the all-off is through."""
    from rti_rig.drivers.led_dome.driver import LedDomeDriver

    real_wait = LedDomeDriver._wait_for_banner
    waits: list[int] = []

    def wait_for_banner(self):  # type: ignore[no-untyped-def]
        waits.append(1)
        if len(waits) <= 2:  # the boot wait, then the stopped connect's wait before its all-off
            signal.raise_signal(signal.SIGINT)
        return real_wait(self)

    monkeypatch.setattr(LedDomeDriver, "_wait_for_banner", wait_for_banner)
    with shipped_dome_on_pty(monkeypatch, SHIPPED) as firmware:
        firmware.boot_delay_s = 1.0
        code, said = _check_said()
    assert code == 130, said
    assert "Traceback" not in said
    assert "all-off sent and acknowledged by the dome: lights are off" in said, said
    assert len(waits) >= 2  # the second Ctrl-C came while the all-off waited for the board
    events = [e.what for e in firmware.history]
    assert firmware.commands_received >= 1 and "lost while booting" not in events, events
    assert firmware.lit is None
