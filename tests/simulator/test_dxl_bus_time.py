"""The emulated arm's ports charge the clock with what a real half-duplex bus takes.

A host on a Dynamixel bus waits, for each exchange, for its instruction's bytes, the servo's
Return Delay Time (9, 2 µs units, factory 250 = 500 µs) and the status's bytes, 10 bits a byte
at the port's baud rate (ROBOTIS e-manual, X series). The in-process port and the pty link's
causal port handed the status over in no time, so a dry run on a ``VirtualClock`` reported an
arm session about 2.5 % short (17.04 s for 6 lights where the bus takes 17.49 s). Each
exchange here is the SDK's own, on a virtual clock: the clock must move by exactly the bus's
time, and by the same on both ports and as the pty server paces a plain port's replies in wall
time (:func:`~rti_rig.simulator.dynamixel_pty.real_time_replies`).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import dynamixel_sdk as sdk
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2
from rti_rig.simulator.dynamixel_emulator import (
    DynamixelBusEmulator,
    EmulatedServo,
    InProcessPort,
)
from rti_rig.simulator.dynamixel_pty import PtyServoServer, real_time_replies

PING_BYTES, PING_STATUS_BYTES = 10, 14  # Ping: header 4, id, LEN 2, inst, CRC 2; + err, 3 params
FACTORY_DELAY_S = 250 * 2e-6


class _LateForSyncWrites(DynamixelBusEmulator):
    """An emulator (thread) that gets round to a Sync Write 50 ms of wall time late: a loaded
    machine's turn, made sure of, where the host goes on at once after the write."""

    def receive(self, data: bytes) -> bytes:
        if len(data) > 7 and data[7] == p2.INST_SYNC_WRITE:
            time.sleep(0.05)
        return super().receive(data)


def _emulator(
    clock: VirtualClock, kind: type[DynamixelBusEmulator] = DynamixelBusEmulator
) -> DynamixelBusEmulator:
    return kind([EmulatedServo(1, 1060, clock), EmulatedServo(2, 1060, clock)], clock)


@contextmanager
def _port(
    kind: str, baud: int, emulator: type[DynamixelBusEmulator] = DynamixelBusEmulator
) -> Iterator[tuple[Any, DynamixelBusEmulator, VirtualClock]]:
    clock = VirtualClock()
    emu = _emulator(clock, emulator)
    for servo in emu.servos.values():  # the servos at the host's rate, as a config sets them
        servo.write(ct.BAUD_RATE.address, bytes([{57600: 1, 1_000_000: 3}[baud]]))
    if kind == "inprocess":
        port = InProcessPort(emu, clock=clock)
        assert port.openPort() and port.setBaudRate(baud)
        yield port, emu, clock
        return
    server = PtyServoServer(emu)
    server.start()
    try:
        port = server.port_handler(clock)
        assert port.openPort() and port.setBaudRate(baud)
        yield port, emu, clock
        port.closePort()
    finally:
        server.stop()


@pytest.mark.parametrize("kind", ["inprocess", "pty"])
@pytest.mark.parametrize("baud", [57600, 1_000_000])
def test_a_ping_costs_its_bytes_on_the_wire_and_the_return_delay_time(kind: str, baud: int) -> None:
    with _port(kind, baud) as (port, _, clock):
        before = clock.now()
        model, result, error = sdk.PacketHandler(2.0).ping(port, 1)
        assert (model, result, error) == (1060, sdk.COMM_SUCCESS, 0)
        spent = clock.now() - before
    wire = (PING_BYTES + PING_STATUS_BYTES) * 10 / baud  # 4.17 ms at 57600, 0.24 ms at 1 Mbps
    assert spent == pytest.approx(wire + FACTORY_DELAY_S, rel=1e-9)


@pytest.mark.parametrize("kind", ["inprocess", "pty"])
def test_a_sync_read_pays_each_servos_own_delay_as_the_paced_pty_does(kind: str) -> None:
    """Two statuses one after the other, each after its own servo's Return Delay Time (servo 2
    set to 0: it is read from the table, not assumed); the clock moves as the pty server paces
    the same replies for a plain port, instruction bytes included."""
    with _port(kind, 1_000_000) as (port, emu, clock):
        emu.servos[2].write(ct.RETURN_DELAY_TIME.address, b"\x00")
        group = sdk.GroupSyncRead(port, sdk.PacketHandler(2.0), ct.PRESENT_POSITION.address, 4)
        assert group.addParam(1) and group.addParam(2)
        before = clock.now()
        assert group.txRxPacket() == sdk.COMM_SUCCESS
        spent = clock.now() - before
    instruction = p2.sync_read(ct.PRESENT_POSITION.address, 4, [1, 2])
    replies = _emulator(VirtualClock()).receive(instruction)
    assert len(instruction) == 16 and len(replies) == 30
    assert spent == pytest.approx((16 + 30) * 10 / 1_000_000 + FACTORY_DELAY_S, rel=1e-9)
    paced = real_time_replies(emu, replies, 1_000_000, heard=len(instruction))
    assert spent == pytest.approx(sum(wait for wait, _ in paced), rel=1e-9)


def test_a_status_the_host_discards_unread_costs_it_nothing() -> None:
    """A status left unread (a unicast write sent TxOnly) and dropped by the next exchange's
    ``clearPort`` is not waited for: only the instruction's bytes are charged."""
    with _port("inprocess", 57600) as (port, _, clock):
        packets = sdk.PacketHandler(2.0)
        before = clock.now()
        assert packets.write1ByteTxOnly(port, 1, ct.LED.address, 1) == sdk.COMM_SUCCESS
        port.clearPort()
        assert clock.now() - before == pytest.approx(13 * 10 / 57600, rel=1e-9)


def _moved_after_a_sync_write(kind: str) -> tuple[int, float]:
    """Present Position read 0.2 s (virtual) after a Sync Write of a slow goal, and the time."""
    with _port(kind, 57600, _LateForSyncWrites) as (port, _, clock):
        packets = sdk.PacketHandler(2.0)
        for reg, value in ((ct.PROFILE_VELOCITY, 10), (ct.TORQUE_ENABLE, 1)):  # 2.3 rpm
            write = {1: packets.write1ByteTxRx, 4: packets.write4ByteTxRx}[reg.size]
            assert write(port, 1, reg.address, value)[0] == sdk.COMM_SUCCESS
        group = sdk.GroupSyncWrite(port, packets, ct.GOAL_POSITION.address, 4)
        assert group.addParam(1, list((3000).to_bytes(4, "little")))
        assert group.txPacket() == sdk.COMM_SUCCESS
        clock.sleep(0.2)  # the host's own wait, at once after a write it reads nothing for
        ticks, result, _ = packets.read4ByteTxRx(port, 1, ct.PRESENT_POSITION.address)
        assert result == sdk.COMM_SUCCESS
        return ticks, clock.now()


def test_the_pty_port_s_write_is_handled_before_the_host_moves_the_clock_on() -> None:
    """The pty's emulator thread reads the clock as it handles an instruction; the host had
    charged the clock (its next bytes, a poll's sleep) while a Sync Write it reads no status
    for was still on its way to the thread, so the goal started late or not by the threads'
    turns, and one plan's dry run took 30.14 s or 30.17 s. The goal starts when its bytes are
    in, on both ports alike."""
    ticks, now = _moved_after_a_sync_write("pty")
    assert (ticks, now) == _moved_after_a_sync_write("inprocess")
    assert ticks > 2048 + 20  # it moved for the 0.2 s, at about 150 ticks a second


@pytest.mark.parametrize("chunk", [1, 3, 64])
def test_a_status_ending_like_a_header_starts_no_packet(chunk: int) -> None:
    """A packet's CRC is not stuffed: servo 1's status with parameters ending ``FF FF``
    (a negative Present Velocity's high bytes) and CRC 0x00FD ends in ``FF FF FD 00``. Read by
    the header alone, that was a packet whose ID was servo 2's next header byte, and servo 2's
    Return Delay Time went uncharged; taken by Length, as the emulator's codec reads, each of
    the two statuses pays its own, in whatever pieces the host reads them."""
    from rti_rig.simulator import dynamixel_wire as wire
    from rti_rig.simulator.dynamixel_bus_time import BusTime

    first = wire.status_packet(1, 0, bytes([163, 83, 0xFF, 0xFF]))
    assert first.endswith(wire.HEADER)  # the case: a header-like run at its very end
    stream = first + wire.status_packet(2, 0, bytes([1, 2, 3, 4]))
    clock = VirtualClock()
    emu = _emulator(clock)
    bus = BusTime(clock, emu.servos, lambda: None)  # no baud: the delays alone
    for i in range(0, len(stream), chunk):
        bus.heard(stream[i : i + chunk])
    assert clock.now() == pytest.approx(2 * FACTORY_DELAY_S, rel=1e-9)


#: The SDK's reply window for a Ping at 57600 baud, s: ``setPacketTimeout(11)``, 11 bytes' wire
#: time plus ``LATENCY_TIMER * 2 + 2`` ms (dynamixel_sdk's PortHandler), about 35.9 ms.
PING_WINDOW_57600_S = 11 * 10 / 57600 + 0.034


@pytest.mark.parametrize("kind", ["inprocess", "pty"])
@pytest.mark.parametrize("fault", ["silent", "drop_reply", "power_lost", "delay_reply:0.2"])
def test_a_status_that_never_comes_in_time_costs_the_host_its_whole_reply_window(
    kind: str, fault: str
) -> None:
    """A real host waits out the SDK's window before it gives up; it had cost the clock the
    instruction's bytes alone, so a dry run with faults was shorter than the real bus."""
    with _port(kind, 57600) as (port, emu, clock):
        if fault == "silent":
            emu.silent_ids.add(1)
        else:
            name, _, delay = fault.partition(":")
            emu.add_fault(emu.instructions_received + 1, name, delay_s=float(delay or 1.0))
        before = clock.now()
        _, result, _ = sdk.PacketHandler(2.0).ping(port, 1)
        assert result == sdk.COMM_RX_TIMEOUT
        spent = clock.now() - before
    assert spent == pytest.approx(PING_BYTES * 10 / 57600 + PING_WINDOW_57600_S, rel=1e-9)


@pytest.mark.parametrize("kind", ["inprocess", "pty"])
def test_a_status_late_within_the_window_costs_the_host_its_lateness(kind: str) -> None:
    """A ``delay_reply`` status 20 ms late, within the window: the host reads it that much
    later (it had cost the clock nothing more than an answer in time)."""
    with _port(kind, 57600) as (port, emu, clock):
        emu.add_fault(emu.instructions_received + 1, "delay_reply", delay_s=0.02)
        before = clock.now()
        model, result, _ = sdk.PacketHandler(2.0).ping(port, 1)
        assert (model, result) == (1060, sdk.COMM_SUCCESS)
        spent = clock.now() - before
    wire = (PING_BYTES + PING_STATUS_BYTES) * 10 / 57600
    assert spent == pytest.approx(wire + 0.02 + FACTORY_DELAY_S, rel=1e-9)
