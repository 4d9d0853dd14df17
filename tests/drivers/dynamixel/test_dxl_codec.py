"""Protocol 2.0 codec against the ROBOTIS e-manual example packets and the SDK's own bytes."""

from __future__ import annotations

import dynamixel_sdk as sdk
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel import protocol2 as p2
from rti_rig.simulator.dynamixel_emulator import DynamixelBusEmulator, EmulatedServo, InProcessPort


def h(text: str) -> bytes:
    return bytes.fromhex(text)


# (built by our codec, expected bytes from the e-manual, protocol2.md examples)
EMANUAL = [
    (p2.ping(1), "FF FF FD 00 01 03 00 01 19 4E"),
    (
        p2.status_packet(1, 0, bytes([0x06, 0x04, 0x26])),
        "FF FF FD 00 01 07 00 55 00 06 04 26 65 5D",
    ),
    (p2.ping(p2.BROADCAST_ID), "FF FF FD 00 FE 03 00 01 31 42"),
    (
        p2.status_packet(2, 0, bytes([0x06, 0x04, 0x26])),
        "FF FF FD 00 02 07 00 55 00 06 04 26 6F 6D",
    ),
    (p2.read(1, 132, 4), "FF FF FD 00 01 07 00 02 84 00 04 00 1D 15"),
    (p2.status_packet(1, 0, p2.u32(166)), "FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0"),
    (p2.write(1, 116, p2.u32(512)), "FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89"),
    (p2.status_packet(1), "FF FF FD 00 01 04 00 55 00 A1 0C"),
    (
        p2.instruction_packet(1, p2.INST_REG_WRITE, p2.u16(104) + p2.u32(200)),
        "FF FF FD 00 01 09 00 04 68 00 C8 00 00 00 AE 8E",
    ),
    (p2.instruction_packet(1, p2.INST_ACTION), "FF FF FD 00 01 03 00 05 02 CE"),
    (p2.instruction_packet(1, p2.INST_FACTORY_RESET, b"\x01"), "FF FF FD 00 01 04 00 06 01 A1 E6"),
    (p2.instruction_packet(1, p2.INST_REBOOT), "FF FF FD 00 01 03 00 08 2F 4E"),
    (
        p2.instruction_packet(1, p2.INST_CLEAR, h("01 44 58 4C 22")),
        "FF FF FD 00 01 08 00 10 01 44 58 4C 22 B1 DC",
    ),
    (p2.sync_read(132, 4, [1, 2]), "FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA"),
    (p2.status_packet(2, 0, p2.u32(2079)), "FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE"),
    (
        p2.sync_write(116, 4, {1: p2.u32(150), 2: p2.u32(170)}),
        "FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87",
    ),
    (
        p2.instruction_packet(
            p2.BROADCAST_ID, p2.INST_BULK_READ, h("01 90 00 02 00 02 92 00 01 00")
        ),
        "FF FF FD 00 FE 0D 00 92 01 90 00 02 00 02 92 00 01 00 1A 05",
    ),
    (p2.status_packet(1, 0, p2.u16(119)), "FF FF FD 00 01 06 00 55 00 77 00 C3 69"),
    (p2.status_packet(2, 0, bytes([36])), "FF FF FD 00 02 05 00 55 00 24 8B A9"),
    (
        p2.instruction_packet(
            p2.BROADCAST_ID, p2.INST_BULK_WRITE, h("01 20 00 02 00 A0 00 02 1F 00 01 00 50")
        ),
        "FF FF FD 00 FE 10 00 93 01 20 00 02 00 A0 00 02 1F 00 01 00 50 B7 68",
    ),
]


@pytest.mark.parametrize(("built", "expected"), EMANUAL)
def test_builders_match_emanual_packets(built: bytes, expected: str) -> None:
    assert built == h(expected)


@pytest.mark.parametrize(("built", "expected"), EMANUAL)
def test_parser_decodes_emanual_packets(built: bytes, expected: str) -> None:
    parser = p2.PacketParser()
    parser.feed(b"\x00\x13" + h(expected))  # leading line noise is skipped
    (pkt,) = parser.packets()
    assert isinstance(pkt, p2.Packet)
    assert pkt.raw == h(expected)
    assert pkt.dxl_id == h(expected)[4]


def test_crc_catalogue_check_value() -> None:
    assert p2.crc16(b"123456789") == 0xFEE8  # CRC-16/BUYPASS
    assert p2.CRC_TABLE[:5] == (0x0000, 0x8005, 0x800F, 0x000A, 0x801B)
    assert p2.CRC_TABLE[-3:] == (0x820D, 0x8207, 0x0202)


def test_corrupted_crc_is_reported_not_decoded() -> None:
    bad = bytearray(h("FF FF FD 00 01 03 00 01 19 4E"))
    bad[-1] ^= 0x01
    parser = p2.PacketParser()
    parser.feed(bytes(bad) + h("FF FF FD 00 01 03 00 01 19 4E"))
    first, second = parser.packets()
    assert isinstance(first, p2.CrcMismatch)
    assert isinstance(second, p2.Packet) and second.instruction == p2.INST_PING


def test_stuffing_inserts_fd_and_lengthens() -> None:
    assert p2.stuff(h("03 74 00 FF FF FD 00")) == h("03 74 00 FF FF FD FD 00")
    stuffed = p2.write(1, 116, p2.u32(0x00FDFFFF))
    assert h("FF FF FD FD") in stuffed[4:]
    assert stuffed[5] == 0x0A  # LEN 9 + 1 stuffed byte
    assert p2.decode(stuffed).params == p2.u16(116) + p2.u32(0x00FDFFFF)


@given(st.binary(max_size=40))
def test_stuff_roundtrip(body: bytes) -> None:
    stuffed = p2.stuff(body)
    assert p2.unstuff(stuffed) == body
    assert stuffed.count(b"\xff\xff\xfd\xfd") >= body.count(b"\xff\xff\xfd")


@given(st.integers(0, 252), st.binary(min_size=0, max_size=30))
def test_parser_takes_unstuffed_sdk_packets_by_length(dxl_id: int, params: bytes) -> None:
    """The SDK sends FF FF FD inside bodies unstuffed; the parser must not resync on it."""
    raw = p2.instruction_packet(dxl_id, p2.INST_WRITE, params, stuffed=False)
    parser = p2.PacketParser()
    for i in range(len(raw)):  # byte by byte, as a serial port delivers them
        parser.feed(raw[i : i + 1])
    packets = parser.packets()
    assert len(packets) == 1 and isinstance(packets[0], p2.Packet)
    assert packets[0].dxl_id == dxl_id


def test_signed_conversion() -> None:
    assert p2.to_signed(0xFFFFFFFF, 4) == -1
    assert p2.to_signed(0x7FFFFFFF, 4) == 2**31 - 1
    assert p2.to_signed(0x8000, 2) == -32768
    assert p2.u32(-3) == h("FD FF FF FF")


def test_sdk_emits_the_emanual_ping_and_unstuffed_writes() -> None:
    """The bytes the real SDK puts on the wire, captured by the in-process port."""
    emu = DynamixelBusEmulator(
        [EmulatedServo(1, 1030, VirtualClock(), operating_mode=4)], VirtualClock()
    )
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)  # the servo's factory rate
    ph = sdk.PacketHandler(2.0)
    assert ph.ping(port, 1) == (1030, sdk.COMM_SUCCESS, 0)
    assert port.tx_log[-1] == h("FF FF FD 00 01 03 00 01 19 4E")
    ph.write1ByteTxRx(port, 1, 64, 1)
    result, error = ph.write4ByteTxRx(port, 1, 116, 0xFFFDFFFF)  # -131073: FF FF FD FF
    assert (result, error) == (sdk.COMM_SUCCESS, 0)
    sent = port.tx_log[-1]
    assert sent[5] == 9 and h("FF FF FD FF") in sent[8:]  # SDK quirk: no stuffing, LEN 9
    assert emu.goal_log[-1] == (1, -131073)
    value, result, _ = ph.read4ByteTxRx(port, 1, 116)
    assert result == sdk.COMM_SUCCESS and p2.to_signed(value, 4) == -131073
