"""`rti-rig check` on the shipped framed-profile dome (``example_dome_48.toml``, its board
emulated on a pty) stopped by Ctrl-C while the dome connects: the all-off is sent once the
board has booted, and the line says what it established, as on the line-protocol firmwares.
A stop inside the port's opening is tested on the default profile too (the shipped
``emulated_dome.toml``): the same driver runs both profiles, and each is covered.

A stop inside the opening of a URL port (``socket://``), whose connect resets nothing, is not
followed by a reopening; and a further Ctrl-C ends a reopening of a serial device at once.

The framed profile's driver had been left out of that fix: a Ctrl-C inside the port's opening
(the system had opened it, which resets an Arduino-class board; pyserial closes it again as the
stop goes through) sent no all-off and said "the dome was never reached", and a Ctrl-C in the
boot wait sent the all-off at once, into the bootloader, where it is lost. The Ctrl-Cs are real
SIGINTs through the check's handler, raised at those points (no race)."""

from __future__ import annotations

import contextlib
import signal
import socket
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


@contextlib.contextmanager
def _listener_that_never_accepts() -> Iterator[tuple[str, int]]:
    """A TCP listener whose backlog is full and which never accepts: a connect to it hangs
    (until pyserial's own 5 s timeout), as one to a dome bridge that is not answering does."""
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(0)
        address = listener.getsockname()
        queued = [socket.socket() for _ in range(8)]
        try:
            for client in queued:
                client.setblocking(False)
                client.connect_ex(address)
            yield address
        finally:
            for client in queued:
                client.close()


def test_a_ctrl_c_while_a_socket_port_connects_ends_the_check_without_a_reopening(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """The shipped framed config with its port a ``socket://`` URL to a listener that never
    accepts. Connecting over TCP toggles no DTR and resets nothing, and this one never
    completed: the check ends at the Ctrl-C, saying the dome was never reached. It had reopened
    the port (a second hanging connect, with a further Ctrl-C held), then said "all-off could
    NOT be sent … lights may still be on" of a dome it never reached."""
    import serial.urlhandler.protocol_socket as protocol_socket

    with _listener_that_never_accepts() as (host, port):
        text = SHIPPED.read_text()
        assert 'profile = "framed"' in text
        config = tmp_path / SHIPPED.name
        config.write_text(
            "\n".join(
                f'port = "socket://{host}:{port}"' if line.startswith("port = ") else line
                for line in text.splitlines()
            )
        )
        lp = SHIPPED.with_suffix(".lp")
        (tmp_path / lp.name).write_bytes(lp.read_bytes())
        real_connect = protocol_socket.socket.create_connection
        attempts: list[object] = []

        def connecting(address, *args, **kwargs):  # type: ignore[no-untyped-def]
            if tuple(address) == (host, port):
                attempts.append(address)
                if len(attempts) == 1:  # the user's Ctrl-C while the connect hangs
                    signal.raise_signal(signal.SIGINT)
            return real_connect(address, *args, **kwargs)

        monkeypatch.setattr(protocol_socket.socket, "create_connection", connecting)
        exit_code, said = _check_said(config)
    assert exit_code == 130, said
    assert "Traceback" not in said
    assert len(attempts) == 1, said  # nothing connected again after the stop
    assert "reopening" not in said, said
    assert "may still be on" not in said, said
    assert "Check stopped (Ctrl-C): no all-off was attempted (the dome was never reached)" in (
        said
    ), said


def test_a_second_sigterm_ends_the_reopening_of_a_port_whose_opening_a_stop_cut_short(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """``rti-rig run`` on the shipped default-profile dome (its emulator on a pty, a serial
    device): a SIGTERM inside the port's opening, which may have reset the board, reopens the
    port for the all-off; a second SIGTERM during that reopening (an open that hangs) ends it
    at once, and the line says the all-off was not sent. The reopening had run with signals
    held, so nothing could end an open that hung. (``run``, not ``check``: the check's handler
    answers any further signal during its teardown with "Still stopping" alone, by design.)"""
    import serial

    emulators = emulators_built_by_check(monkeypatch)
    redirected = serial.serial_for_url
    openings: list[int] = []

    def opened(*args, **kwargs):  # type: ignore[no-untyped-def]
        openings.append(1)
        if len(openings) == 2:  # the second stop, while the port is being opened again
            signal.raise_signal(signal.SIGTERM)
        port = redirected(*args, **kwargs)
        if len(openings) == 1:  # the first stop, inside the first opening
            try:
                signal.raise_signal(signal.SIGTERM)
            except BaseException:
                port.close()  # as pyserial's own open does when a stop goes through it
                raise
        return port

    monkeypatch.setattr(serial, "serial_for_url", opened)
    config = BY_PROFILE["default"]
    r = CliRunner().invoke(
        app, ["run", str(config), "--out", str(tmp_path / "out")], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 143, said
    assert "Traceback" not in said
    assert len(openings) == 2, said
    assert (
        "Emergency stop (SIGTERM): all-off could NOT be sent (a further stop ended the "
        "reopening of the port a stop had cut short)"
    ) in said, said
    firmware = emulators[-1]
    assert [e.what for e in firmware.history].count("boot") == 1  # not opened again
    assert firmware.commands_received == 0
