"""The servo's side of Dynamixel Protocol 2.0: instruction packets in, status packets out,
written from the ROBOTIS e-manual's Protocol 2.0 page alone
(https://emanual.robotis.com/docs/en/dxl/protocol2/, ROBOTIS-GIT/emanual
docs/en/dxl/protocol2.md @ 01179568a085cfc99bdad6e880e43fa871bd318a) and the CRC page it links to.

Why its own codec: the emulator had read and written the wire with the driver's
(``rti_rig.drivers.dynamixel.protocol2``), so a codec bug would have been on both sides of the
wire, invisible to every driver test against the emulator. An import-linter contract in
pyproject.toml keeps this module and the emulator off the driver's codec.

What the page says, and this module does:

- Packet: ``FF FF FD`` (Header) ``00`` (Reserved, "functions the same as Header"), Packet ID,
  Length (low, high) = the Instruction, the Parameters and the two CRC bytes, Instruction,
  Parameters, CRC (low, high). A status packet's Instruction is ``0x55``, followed by the Error
  byte (bit 7 Alert, bits 0-6 the error number).
- IDs 0..252 are devices, 254 (``0xFE``) is broadcast; 253 and 255 are never a packet's ID.
- Transmission: byte stuffing over the Instruction through the last Parameter (not the CRC):
  after every ``FF FF FD`` an extra ``FD``; Length counts the stuffed bytes; the CRC is over the
  stuffed packet.
- Reception: find the header, take Length bytes more, check the CRC over the packet as
  received (stuffing included), only then remove the stuffing.
- CRC: CRC-16, polynomial x^16 + x^15 + x^2 + 1 (``0x8005``), initial value 0, MSB first
  through a 256-entry table (the CRC page's ``update_crc``), sent low byte first.

Reading by Length, never by a header found inside a body, also takes the packets the official
SDK sends unstuffed (its ``txPacket`` drops ``addStuffing``'s result), as a servo does.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Header 1-3 and Reserved: every packet begins with them.
HEADER = b"\xff\xff\xfd\x00"
#: Packet ID that makes every device execute the instruction.
BROADCAST_ID = 0xFE
#: The largest device ID (0..252; 253 and 255 are never used, to avoid a header).
MAX_DEVICE_ID = 0xFC

# The Instruction field's values (e-manual, Protocol 2.0, Instruction).
PING = 0x01
READ = 0x02
WRITE = 0x03
REG_WRITE = 0x04
ACTION = 0x05
FACTORY_RESET = 0x06
REBOOT = 0x08
CLEAR = 0x10
STATUS = 0x55
SYNC_READ = 0x82
SYNC_WRITE = 0x83
BULK_READ = 0x92
BULK_WRITE = 0x93

# The status packet's Error byte (e-manual, Protocol 2.0, Status Packet, Error).
ALERT = 0x80
RESULT_FAIL = 0x01
INSTRUCTION_ERROR = 0x02
CRC_ERROR = 0x03
DATA_RANGE_ERROR = 0x04
DATA_LENGTH_ERROR = 0x05
DATA_LIMIT_ERROR = 0x06
ACCESS_ERROR = 0x07

#: x^16 + x^15 + x^2 + 1, the CRC page's polynomial
CRC_POLYNOMIAL = 0x8005


def _crc_table() -> tuple[int, ...]:
    """The CRC page's 256-entry table: entry ``i`` is ``i << 8`` divided by the polynomial,
    MSB first (its first entries 0x0000, 0x8005, 0x800F, 0x000A, ...)."""
    table = []
    for i in range(256):
        crc = i << 8
        for _ in range(8):
            crc = (crc << 1) ^ CRC_POLYNOMIAL if crc & 0x8000 else crc << 1
        table.append(crc & 0xFFFF)
    return tuple(table)


CRC_TABLE = _crc_table()


def crc(data: bytes | bytearray) -> int:
    """The packet CRC of ``data`` (the CRC page's ``update_crc`` from 0)."""
    value = 0
    for byte in data:
        value = ((value << 8) ^ CRC_TABLE[((value >> 8) ^ byte) & 0xFF]) & 0xFFFF
    return value


def add_stuffing(body: bytes) -> bytes:
    """``body`` (Instruction .. last Parameter) with an ``FD`` added after every ``FF FF FD``.

    An added ``FD`` never begins a new pattern (one needs ``FF FF`` before its ``FD``), so the
    pattern is looked for in what has been written so far."""
    out = bytearray()
    for byte in body:
        out.append(byte)
        if out[-3:] == b"\xff\xff\xfd":
            out.append(0xFD)
    return bytes(out)


def remove_stuffing(body: bytes) -> bytes:
    """Undo :func:`add_stuffing`: the ``FD`` after each ``FF FF FD`` is dropped."""
    out = bytearray()
    i = 0
    while i < len(body):
        out.append(body[i])
        if out[-3:] == b"\xff\xff\xfd" and body[i + 1 : i + 2] == b"\xfd":
            i += 1  # the stuffed FD
        i += 1
    return bytes(out)


def status_packet(dxl_id: int, error: int = 0, params: bytes = b"") -> bytes:
    """The bytes of a status packet from device ``dxl_id``: stuffed, Length counting the
    stuffed body and the CRC, the CRC over the stuffed packet, low byte first."""
    if not 0 <= dxl_id <= MAX_DEVICE_ID:
        raise ValueError(f"a status packet comes from a device id 0..252, not {dxl_id}")
    body = add_stuffing(bytes([STATUS, error]) + bytes(params))
    length = len(body) + 2
    packet = HEADER + bytes([dxl_id, length & 0xFF, length >> 8]) + body
    value = crc(packet)
    return packet + bytes([value & 0xFF, value >> 8])


@dataclass(frozen=True)
class Instruction:
    """An instruction packet as a servo takes it: its Packet ID, Instruction and Parameters
    (stuffing removed), and the bytes as received."""

    dxl_id: int
    instruction: int
    params: bytes
    raw: bytes = b""


@dataclass(frozen=True)
class BadCrc:
    """A whole packet whose CRC did not match (the e-manual's CRC Error); ``raw`` as received."""

    raw: bytes

    @property
    def dxl_id(self) -> int:
        return self.raw[4]


def begins_packet(dxl_id: int, length: int) -> bool:
    """Whether a header followed by ``dxl_id`` and ``length`` can begin a packet: no packet
    carries ID 253 (0xFD, it would read as a header) or 255, and Length counts at least the
    Instruction (or a status's Error) and the CRC. One rule for every reader of the stream
    (this module's :class:`InstructionReader`, the bus time's status reader)."""
    return dxl_id <= BROADCAST_ID and dxl_id != 0xFD and length >= 3


class InstructionReader:
    """The reception order of the e-manual, over a byte stream: ``feed`` bytes, then take
    :meth:`packets`.

    Bytes before a header are line noise and dropped; a header followed by an ID no packet
    carries (253, 255) is skipped; otherwise Length more bytes make the packet, whose CRC is
    checked before the stuffing is removed. A packet still arriving stays buffered."""

    def __init__(self) -> None:
        self._buf = bytearray()

    def feed(self, data: bytes) -> None:
        self._buf += data

    def packets(self) -> list[Instruction | BadCrc]:
        out: list[Instruction | BadCrc] = []
        while True:
            start = self._buf.find(HEADER)
            if start < 0:
                keep = min(len(self._buf), len(HEADER) - 1)  # a header cut in two
                del self._buf[: len(self._buf) - keep]
                return out
            del self._buf[:start]
            if len(self._buf) < 7:
                return out
            dxl_id = self._buf[4]
            length = self._buf[5] | self._buf[6] << 8
            if not begins_packet(dxl_id, length):
                del self._buf[: len(HEADER)]  # not a packet: look for the next header
                continue
            if len(self._buf) < 7 + length:
                return out
            raw = bytes(self._buf[: 7 + length])
            del self._buf[: 7 + length]
            if crc(raw[:-2]) != raw[-2] | raw[-1] << 8:
                out.append(BadCrc(raw))
                continue
            body = remove_stuffing(raw[7:-2])
            out.append(Instruction(dxl_id, body[0], body[1:], raw))


def signed(value: int, size: int) -> int:
    """A register's unsigned bytes as the two's complement the X-series control table uses
    for its signed items (Goal Position in extended position mode, Present Velocity...)."""
    bits = 8 * size
    value &= (1 << bits) - 1
    return value - (1 << bits) if value >> (bits - 1) else value
