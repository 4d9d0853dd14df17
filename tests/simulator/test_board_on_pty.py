"""Real-firmware emulators served on a pty behave as the boards do at the port, whatever the host.

Each test opens the pty with real pyserial, as a host program does. Waits are bounded reads of
seconds, never timing asserts, so CPU load cannot fail them.
"""

from __future__ import annotations

import sys
import time

import pytest
import serial
from conftest import eventually

from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: The last line of the Nab sketch's boot banner (``setup()`` of the "RTI v1.0" sketch).
NAB_BANNER_END = b"<6> Single photo\r\n===================\r\n"


def read_until(port: serial.Serial, end: bytes, timeout_s: float = 10.0) -> bytes:
    """What the board sent up to and including ``end`` (or all it sent within the bound)."""
    heard = bytearray()
    deadline = time.monotonic() + timeout_s
    while end not in heard and time.monotonic() < deadline:
        heard += port.read(max(1, port.in_waiting))
    return bytes(heard)


def boots(board) -> int:  # type: ignore[no-untyped-def]
    return sum(1 for _, what in board.events if what == "boot")


def test_a_quick_close_and_reopen_resets_the_board_again() -> None:
    """An Arduino resets at every open (DTR), however soon after a close: the emulator too.

    ``rti-rig probe`` closes the port and opens it again at once for its next question. The
    server had seen only the first open (it looked for the master's hang-up, which a reopen
    within microseconds never shows), so the board went on where it was: the Nab sketch booted
    once for two opens, and RTIPy's reply to one probe reached the next one.
    """
    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab") as link:
        port = serial.Serial(link.port, 9600, timeout=0.1)
        assert read_until(port, NAB_BANNER_END).endswith(NAB_BANNER_END)
        # The server thread is held in the board (its lock) while the port is closed and
        # opened again: the reopen then surely comes before the server polls, as it does when
        # the CPU is busy or the host is quick, so the test does not depend on the scheduler.
        with board._lock:
            time.sleep(0.2)  # the server reaches the board's lock and waits there
            port.close()
            port = serial.Serial(link.port, 9600, timeout=0.1)
        with port:
            second = read_until(port, NAB_BANNER_END)
        assert b"RTI-Dome intialized" in second, second
        assert boots(board) == 2
        # and it booted lit again, as the sketch's setup() does at every reset
        assert board.lit == frozenset(range(64))


def test_a_native_usb_board_works_at_any_baud_rate() -> None:
    """hadrian2/RTI_Dome runs on an ATmega32u4 (``ATMEGA_code.txt`` drives ``LED_BUILTIN_TX``,
    a 32u4 board's pin, and uses the UART's pins 0 and 1 as outputs): its ``Serial`` is USB
    CDC, where ``Serial.begin(9600)`` sets no rate, so a host at 115200 still reaches it. The
    emulator had garbled every byte at a rate other than 9600, as for a board behind a UART."""
    board = board_for("rti-dome-m")
    with (
        serve_on_pty(board, "rti-dome") as link,
        serial.Serial(link.port, 115200, timeout=0.1) as port,
    ):
        port.write(b"M5")
        assert eventually(lambda: board.lit == frozenset({5})), board.timeline


def test_a_board_behind_a_uart_still_hears_garbage_at_another_rate() -> None:
    """The Nab sketch's Uno talks through its USB-serial chip's UART at 9600 (``Serial.begin``):
    at 115200 its banner is unreadable and ``<3,5>`` lights nothing."""
    board = board_for("nab-rti-v1")
    with (
        serve_on_pty(board, "nab") as link,
        serial.Serial(link.port, 115200, timeout=0.1) as port,
    ):
        heard = read_until(port, NAB_BANNER_END, timeout_s=3.0)
        assert b"RTI-Dome" not in heard
        port.write(b"<0><3,5>")
        time.sleep(0.5)
    assert board.lit != frozenset({5})


def test_a_node_that_cannot_be_watched_falls_back_on_the_hang_up(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Where inotify cannot watch the pty's node, an open is still seen (by the master's
    hang-up ending), so the board still boots when the host opens the port."""
    from rti_rig.simulator import pty_link

    def refused(self, path: str) -> None:  # type: ignore[no-untyped-def]
        self.wd, self._failed = -1, True

    monkeypatch.setattr(pty_link._OpenWatch, "watch", refused)
    board = board_for("nab-rti-v1")
    with (
        serve_on_pty(board, "nab") as link,
        serial.Serial(link.port, 9600, timeout=0.1) as port,
    ):
        assert read_until(port, NAB_BANNER_END).endswith(NAB_BANNER_END)


def test_an_open_unread_when_the_server_stops_still_resets_the_board(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A host that opened and closed the port just before the emulator was stopped (a stop
    inside pyserial's open, the rig then closed): the open, not yet read by the server's loop,
    still resets the board, as DTR rising resets a real one. The Nab board then boots with every
    LED lit; read once its bootloader is over (``lit`` reads empty while it is in it, as for a
    board that was never opened). The server is stopped before it runs, so the open is unread."""
    import os
    import threading

    from rti_rig.simulator.pty_link import _Server

    board = board_for("nab-rti-v1")
    stop = threading.Event()
    stop.set()
    server = _Server(board, tmp_path / "tty-nab", stop)
    server.new_pty()
    assert server.watch.available  # inotify, on Linux: every open is seen
    fd = os.open(tmp_path / "tty-nab", os.O_RDWR | os.O_NOCTTY)  # the host's open and close
    os.close(fd)
    server.run()  # the loop ends at once: the open was never read by it
    assert boots(board) == 1
    assert board.lit_once_booted() == frozenset(range(board.led_count))  # never sent the all-off


def touches(board) -> int:  # type: ignore[no-untyped-def]
    return sum(1 for _, what in board.events if what == "bootloader (1200-baud touch)")


@pytest.mark.parametrize(("baud", "jumps"), [(1200, 1), (9600, 0)])
def test_closing_the_32u4_port_at_1200_baud_drops_it_into_its_bootloader(
    baud: int, jumps: int
) -> None:
    """The ATmega32u4 core's USB code jumps to the bootloader when a port set to 1200 baud
    drops DTR (the Arduino "1200-baud touch"): the sketch stops for the bootloader's 8 s and
    the M5 sent once the port is opened again never reaches it. At any other rate a
    close changes nothing (the board does not even reset when the port opens)."""
    board = board_for("rti-dome-m")
    board.bootloader_wait_s = 600.0  # however slow the host, the M5 comes while it waits
    with serve_on_pty(board, "rti-dome") as link:
        port = serial.Serial(link.port, baud, timeout=0.1)
        assert eventually(lambda: board.host_baud == baud), board.host_baud
        port.close()
        if jumps:
            assert eventually(lambda: touches(board) == 1), board.events
        with serial.Serial(link.port, 9600, timeout=0.1) as port:
            port.write(b"M5 ")
            port.flush()
            # what the board makes of it is settled once the pty handed the bytes over: the
            # sketch, if running, lights LED 5 at once (the space ends parseInt)
            heard = eventually(
                lambda: board.lit == frozenset({5}), timeout_s=3.0 if jumps else 10.0
            )
    assert touches(board) == jumps, board.events
    assert heard is not bool(jumps), board.timeline


def test_every_device_served_on_a_pty_declares_what_the_server_calls() -> None:
    """The server calls each member of :class:`PtyDevice` on the device it serves; a port's
    close (``on_port_closed``) had been probed with ``getattr``, so a device that misspelt it
    went unheard. Both emulators served on a pty declare every member."""
    from rti_rig.simulator.dome_firmware import DomeFirmware
    from rti_rig.simulator.domes.board import Board
    from rti_rig.simulator.pty_link import PtyDevice

    members = [n for n, v in vars(PtyDevice).items() if callable(v) and not n.startswith("_")]
    assert "on_port_closed" in members, members
    for device in (Board, DomeFirmware):
        missing = [n for n in members if not callable(getattr(device, n, None))]
        assert not missing, (device, missing)


def test_a_board_declares_the_host_s_rate_and_its_own_time_which_the_server_serves() -> None:
    """The server tells a device the host's UART rate and ticks its clock only where the
    device declares them (:class:`HostBaudDevice`, :class:`TickingDevice`): it had probed by
    name, so a board whose ``tick`` was misspelt would have sat unticked, unsaid. Every board
    declares both (``tick`` abstract: a board without it cannot be built); the scripted
    firmware, which keeps no time of its own and reads any rate, declares neither."""
    from rti_rig.simulator.dome_firmware import DomeFirmware
    from rti_rig.simulator.domes.board import Board
    from rti_rig.simulator.pty_link import HostBaudDevice, TickingDevice

    for declared in (HostBaudDevice, TickingDevice):
        assert declared in Board.__mro__ and declared not in DomeFirmware.__mro__, declared
    assert "tick" in TickingDevice.__abstractmethods__
