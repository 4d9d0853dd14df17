"""A servo's ID as the bus meets it, through the real dynamixel_sdk: a servo whose ID (7) is
written answers at its new ID, and two servos at one ID both hear it and answer together.

ROBOTIS e-manual, Protocol 2.0, ID: "Each connected DYNAMIXEL must have a unique ID number.
If DYNAMIXELs with the same ID are connected, packet collision and network problems will
occur." The emulator had kept its servos by the IDs they started with: a servo given a new
ID went on answering at its old one, and a Factory Reset 0xFF (ID back to 1) on a bus where
another servo had ID 1 dropped one of the two from the bus, which then answered cleanly."""

from __future__ import annotations

import dynamixel_sdk as sdk

from rti_rig.core.clock import VirtualClock
from rti_rig.simulator import dynamixel_table as tbl
from rti_rig.simulator.dynamixel_emulator import (
    RESTART_S,
    DynamixelBusEmulator,
    EmulatedServo,
    InProcessPort,
)


def _bus(*ids: int):  # type: ignore[no-untyped-def]
    clock = VirtualClock()
    emu = DynamixelBusEmulator([EmulatedServo(i, 1060, clock) for i in ids], clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)
    return emu, port, sdk.PacketHandler(2.0), clock


def test_a_servo_given_a_new_id_answers_at_it_and_no_longer_at_the_old() -> None:
    emu, port, ph, _ = _bus(1, 2)
    # the write's status goes out as the ID the packet reached
    assert ph.write1ByteTxRx(port, 1, tbl.ID.address, 5) == (sdk.COMM_SUCCESS, 0)
    assert ph.ping(port, 5) == (1060, sdk.COMM_SUCCESS, 0)
    assert ph.ping(port, 1)[1] == sdk.COMM_RX_TIMEOUT
    assert sorted(emu.servos) == [2, 5]
    assert ph.write1ByteTxRx(port, 5, tbl.LED.address, 1) == (sdk.COMM_SUCCESS, 0)
    assert emu.servos[5].get(tbl.LED) == 1 and emu.servos[2].get(tbl.LED) == 0


def test_a_factory_reset_to_id_1_beside_a_servo_at_1_leaves_two_that_collide() -> None:
    emu, port, ph, clock = _bus(1, 2)
    assert ph.factoryReset(port, 2, 0xFF) == (sdk.COMM_SUCCESS, 0)
    clock.sleep(RESTART_S)
    assert ph.ping(port, 2)[1] == sdk.COMM_RX_TIMEOUT
    # both answer at once: the host reads neither's status (a retry meets the same)
    assert ph.ping(port, 1)[1] == sdk.COMM_RX_CORRUPT
    assert [s.dxl_id for s in emu.chain] == [1, 1]  # both still on the bus
    assert ph.read1ByteTxRx(port, 1, tbl.LED.address)[1] == sdk.COMM_RX_CORRUPT
    # both hear a write to ID 1 and act on it: the one that was servo 2 cannot be told apart
    assert ph.write1ByteTxOnly(port, 1, tbl.LED.address, 1) == sdk.COMM_SUCCESS
    assert [s.get(tbl.LED) for s in emu.chain] == [1, 1]
    group = sdk.GroupSyncRead(port, ph, tbl.LED.address, 1)
    assert group.addParam(1) and group.txRxPacket() != sdk.COMM_SUCCESS
