"""A plain port's status comes the Return Delay Time after the instruction was *read*.

``PtyServoServer._serve`` slept each reply's wait (:func:`real_time_replies`: the servo's Return
Delay Time (9), 2 µs units, factory 250 = 500 µs, plus wire time) after it had handled the
instruction, so an emulator thread that was itself late (a loaded host, the GIL) added the
delay on top of its lateness. A real servo counts the delay from the instruction's last byte
(ROBOTIS e-manual, X series, Return Delay Time). The server's clock and sleep are injected: no
wall time is measured here.
"""

from __future__ import annotations

import os
import select
import termios
import time
import tty

import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel import protocol2 as p2
from rti_rig.simulator.dynamixel_emulator import DynamixelBusEmulator, EmulatedServo
from rti_rig.simulator.dynamixel_pty import PtyServoServer, real_time_replies


class _LateThread:
    """A wall clock on which each reading comes ``step_s`` after the one before (the serving
    thread late by that much between reading the instruction and pacing its answer); a sleep
    moves it on by what was slept, and is recorded."""

    def __init__(self, step_s: float) -> None:
        self.now = 100.0
        self.step_s = step_s
        self.slept: list[float] = []

    def monotonic(self) -> float:
        self.now += self.step_s
        return self.now

    def sleep(self, s: float) -> None:
        self.slept.append(s)
        self.now += s


def _server(clock: _LateThread) -> PtyServoServer:
    vclock = VirtualClock()
    emu = DynamixelBusEmulator([EmulatedServo(1, 1060, vclock)], vclock)
    return PtyServoServer(emu, monotonic=clock.monotonic, sleep=clock.sleep)


def test_each_wait_counts_from_the_read_not_from_the_thread_s_turn() -> None:
    clock = _LateThread(0.0003)  # the thread 0.3 ms late: 0.2 ms of the 0.5 ms delay left
    read_fd, write_fd = os.pipe()
    try:
        _server(clock)._write_paced(write_fd, [(0.0005, b"ab"), (0.001, b"cd")], 100.0)
        assert os.read(read_fd, 16) == b"abcd"
    finally:
        os.close(read_fd)
        os.close(write_fd)
    # 100.0003 → 100.0005 (0.2 ms), then 100.0008 → 100.0015, the second packet's own 1 ms due
    assert clock.slept == [pytest.approx(0.0002), pytest.approx(0.0007)]
    late = _LateThread(0.01)  # a thread later than the whole delay: it answers at once
    read_fd, write_fd = os.pipe()
    try:
        _server(late)._write_paced(write_fd, [(0.0005, b"ab")], 100.0)
        assert os.read(read_fd, 16) == b"ab"
    finally:
        os.close(read_fd)
        os.close(write_fd)
    assert late.slept == []


@pytest.mark.pty
def test_a_served_ping_is_answered_its_delay_after_it_was_read() -> None:
    """Through the served pty: the one wait slept is the ping's reply wait less the time the
    thread took after reading it (one clock step), not the whole wait after that step."""
    clock = _LateThread(0.0002)
    with _server(clock) as server:
        assert server.device_path is not None
        fd = os.open(server.device_path, os.O_RDWR | os.O_NOCTTY)
        try:
            tty.setraw(fd)
            attrs = termios.tcgetattr(fd)
            attrs[4] = attrs[5] = termios.B57600
            termios.tcsetattr(fd, termios.TCSANOW, attrs)
            ping = p2.ping(1)
            os.write(fd, ping)
            got = b""
            deadline = time.monotonic() + 30  # generous: the emulator thread may be starved
            while len(got) < 14 and time.monotonic() < deadline:
                if select.select([fd], [], [], 1.0)[0]:
                    got += os.read(fd, 64)
        finally:
            os.close(fd)
    assert len(got) == 14 and got[4] == 1, got  # servo 1's ping status, whole
    ((wait_s, _),) = real_time_replies(server.emulator, got, 57600, len(ping))
    assert wait_s > 0.0005  # the factory delay and the wire time
    assert clock.slept == [pytest.approx(wait_s - 0.0002)]
