"""The emulated servos answer the ROBOTIS e-manual's own example packets byte for byte.

Every packet below is copied from the e-manual's Protocol 2.0 page, "Instruction Details"
(https://emanual.robotis.com/docs/en/dxl/protocol2/, ROBOTIS-GIT/emanual
docs/en/dxl/protocol2.md @ 01179568a085cfc99bdad6e880e43fa871bd318a), whose examples are
XM430-W210 servos (model 1030, firmware 38). The emulator reads and writes them with its own
codec (rti_rig.simulator.dynamixel_wire), never the driver's: these bytes are the only
reference both sides answer to.
"""

from __future__ import annotations

import dynamixel_sdk as sdk
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.simulator import dynamixel_wire as wire
from rti_rig.simulator.dynamixel_emulator import DynamixelBusEmulator, EmulatedServo, InProcessPort

XM430_W210 = 1030
#: Operating Mode (11) 1, Velocity Control (e-manual, XM430-W210 control table)
VELOCITY_CONTROL = 1


def packet(text: str) -> bytes:
    return bytes.fromhex(text)


def xm430s(*present: int, mode: int = ct.OperatingMode.POSITION) -> DynamixelBusEmulator:
    """The examples' servos: IDs 1, 2... XM430-W210 at firmware 38, at these positions."""
    clock = VirtualClock()
    servos = [
        EmulatedServo(i + 1, XM430_W210, clock, firmware=38, present_ticks=p, operating_mode=mode)
        for i, p in enumerate(present)
    ]
    return DynamixelBusEmulator(servos, clock)


# e-manual, Protocol 2.0, Write / Reg Write / Action / Reboot / Clear examples: ID 1's status
OK_1 = "FF FF FD 00 01 04 00 55 00 A1 0C"


def test_ping_unicast_and_broadcast() -> None:
    # Ping, Example 1: ID 1 answers its model 1030 (06 04) and firmware 38 (26)
    bus = xm430s(2048, 2048)
    assert bus.receive(packet("FF FF FD 00 01 03 00 01 19 4E")) == packet(
        "FF FF FD 00 01 07 00 55 00 06 04 26 65 5D"
    )
    # Ping, Example 2: to the broadcast ID each device answers, in order of ID
    assert bus.receive(packet("FF FF FD 00 FE 03 00 01 31 42")) == packet(
        "FF FF FD 00 01 07 00 55 00 06 04 26 65 5D" + "FF FF FD 00 02 07 00 55 00 06 04 26 6F 6D"
    )


def test_read_present_position() -> None:
    # Read, Example: Present Position (132, 4 bytes) = 166
    bus = xm430s(166)
    assert bus.receive(packet("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15")) == packet(
        "FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0"
    )


def test_write_goal_position() -> None:
    # Write, Example: 512 to Goal Position (116, 4 bytes)
    bus = xm430s(2048)
    assert bus.receive(packet("FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89")) == packet(OK_1)
    assert bus.servos[1].get(ct.GOAL_POSITION) == 512


def test_reg_write_then_action() -> None:
    # Reg Write, Example: 200 to Goal Velocity (104, 4 bytes), held until the Action
    bus = xm430s(2048, mode=VELOCITY_CONTROL)
    servo = bus.servos[1]
    reg_write = packet("FF FF FD 00 01 09 00 04 68 00 C8 00 00 00 AE 8E")
    assert bus.receive(reg_write) == packet(OK_1)
    assert servo.get(ct.REGISTERED_INSTRUCTION) == 1
    assert servo.get(ct.GOAL_VELOCITY) == 0
    # Action, Example: the registered write is executed
    assert bus.receive(packet("FF FF FD 00 01 03 00 05 02 CE")) == packet(OK_1)
    assert servo.get(ct.GOAL_VELOCITY) == 200
    assert servo.get(ct.REGISTERED_INSTRUCTION) == 0


def test_reboot_and_clear() -> None:
    bus = xm430s(2048)
    # Clear, Example: multi-turn information reset on a servo at rest
    clear = packet("FF FF FD 00 01 08 00 10 01 44 58 4C 22 B1 DC")
    assert bus.receive(clear) == packet(OK_1)
    # Reboot, Example
    assert bus.receive(packet("FF FF FD 00 01 03 00 08 2F 4E")) == packet(OK_1)


def test_sync_read_present_positions() -> None:
    # Sync Read, Example: Present Position of ID 1 (166) and ID 2 (2079), a status each
    bus = xm430s(166, 2079)
    assert bus.receive(packet("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA")) == packet(
        "FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0"
        + "FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE"
    )


def test_sync_write_goal_positions() -> None:
    # Sync Write, Example: Goal Position 150 to ID 1, 170 to ID 2; no status
    bus = xm430s(2048, 2048)
    sync_write = packet(
        "FF FF FD 00 FE 11 00 83 74 00 04 00" + "01 96 00 00 00 02 AA 00 00 00 82 87"
    )
    assert bus.receive(sync_write) == b""
    assert (bus.servos[1].get(ct.GOAL_POSITION), bus.servos[2].get(ct.GOAL_POSITION)) == (150, 170)


def test_bulk_read_and_bulk_write() -> None:
    bus = xm430s(2048, 2048)
    # Bulk Read, Example: ID 1's Present Input Voltage (144, 2 bytes) = 119, ID 2's Present
    # Temperature (146, 1 byte) = 36
    bus.set_input_voltage(1, 119)
    bus.servos[2].table[ct.PRESENT_TEMPERATURE.address] = 36
    bulk_read = packet("FF FF FD 00 FE 0D 00 92 01 90 00 02 00" + "02 92 00 01 00 1A 05")
    assert bus.receive(bulk_read) == packet(
        "FF FF FD 00 01 06 00 55 00 77 00 C3 69" + "FF FF FD 00 02 05 00 55 00 24 8B A9"
    )
    # Bulk Write, Example: ID 1's Max Voltage Limit (32, 2 bytes) 160, ID 2's Temperature
    # Limit (31, 1 byte) 80; no status
    bulk_write = packet("FF FF FD 00 FE 10 00 93 01 20 00 02 00 A0 00" + "02 1F 00 01 00 50 B7 68")
    assert bus.receive(bulk_write) == b""
    assert bus.servos[1].get(ct.MAX_VOLTAGE_LIMIT) == 160
    assert bus.servos[2].get(ct.TEMPERATURE_LIMIT) == 80


def test_a_damaged_packet_gets_a_crc_error() -> None:
    # the Read example with its last CRC byte damaged: Error 0x03, "CRC of the sent Packet
    # does not match" (Status Packet, Error); the status is built by the page's rules
    bus = xm430s(166)
    reply = bus.receive(packet("FF FF FD 00 01 07 00 02 84 00 04 00 1D 16"))
    assert reply == wire.status_packet(1, wire.CRC_ERROR)
    assert reply[7:9] == bytes([0x55, 0x03])


def test_the_crc_table_is_the_crc_pages() -> None:
    # CRC page (https://emanual.robotis.com/docs/en/dxl/crc/), crc_table's first row
    assert wire.CRC_TABLE[:8] == (0x0000, 0x8005, 0x800F, 0x000A, 0x801B, 0x001E, 0x0014, 0x8011)
    # and a whole example packet: the Ping of Example 1, CRC 19 4E sent low byte first
    assert wire.crc(packet("FF FF FD 00 01 03 00 01")) == 0x4E19


def test_stuffing_as_the_page_describes_it() -> None:
    # Packet Process: "If 'FF FF FD' already exists, add a 0xFD to change it to
    # 'FF FF FD FD'"; Length and CRC count the stuffed bytes
    body = bytes([0x55, 0x00, 0xFF, 0xFF, 0xFD, 0xFF])
    assert wire.add_stuffing(body) == bytes([0x55, 0x00, 0xFF, 0xFF, 0xFD, 0xFD, 0xFF])
    assert wire.remove_stuffing(wire.add_stuffing(body)) == body
    status = wire.status_packet(1, 0, body[2:])
    assert status[5] | status[6] << 8 == 7 + 2
    assert wire.crc(status[:-2]) == status[-2] | status[-1] << 8


@pytest.mark.parametrize("goal", [-131073, 0x000FFDFF])
def test_the_official_sdk_reads_back_a_value_that_needs_stuffing(goal: int) -> None:
    """Goal Position -131073 is FF FF FD FF on the wire: the SDK sends it unstuffed (its
    quirk), the servo reads it by Length; the status is stuffed and the SDK, unchanged,
    removes the stuffing. 0x000FFDFF has FF FD without a second FF: nothing to stuff."""
    bus = xm430s(2048, mode=ct.OperatingMode.EXTENDED_POSITION)
    port = InProcessPort(bus)
    assert port.setBaudRate(57600) and port.openPort()  # the servos' factory rate
    handler = sdk.PacketHandler(2.0)
    value = goal & 0xFFFFFFFF
    result, error = handler.write4ByteTxRx(port, 1, ct.GOAL_POSITION.address, value)
    assert (result, error) == (sdk.COMM_SUCCESS, 0)
    read, result, error = handler.read4ByteTxRx(port, 1, ct.GOAL_POSITION.address)
    assert (read, result, error) == (value, sdk.COMM_SUCCESS, 0)
    assert bus.servos[1].get(ct.GOAL_POSITION) == goal
