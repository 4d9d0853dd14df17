"""Dynamixel Protocol 2.0 packet codec: pure functions, no I/O.

Why our own codec when the SDK has one: the emulator must *parse instruction packets* (the SDK
only builds them), tests must compare bytes against the ROBOTIS e-manual examples, and the SDK's
sender has a known quirk (it sends instruction packets without byte stuffing, because
``txPacket`` ignores the return value of ``addStuffing``). So the parser here works *by length*
and never resynchronises on a header found inside a packet body, and it still accepts properly
stuffed packets from other clients.

Layout: ``FF FF FD 00 | ID | LEN_L LEN_H | INST | PARAM... | CRC_L CRC_H``; LEN counts INST,
params and CRC. Status packets have INST 0x55 followed by an ERR byte. CRC-16/BUYPASS
(polynomial 0x8005, init 0, no reflection) over every byte before the CRC, sent low byte first.
"""

from __future__ import annotations

from dataclasses import dataclass

HEADER = b"\xff\xff\xfd\x00"
BROADCAST_ID = 0xFE
MAX_ID = 0xFC

INST_PING = 0x01
INST_READ = 0x02
INST_WRITE = 0x03
INST_REG_WRITE = 0x04
INST_ACTION = 0x05
INST_FACTORY_RESET = 0x06
INST_REBOOT = 0x08
INST_CLEAR = 0x10
INST_STATUS = 0x55
INST_SYNC_READ = 0x82
INST_SYNC_WRITE = 0x83
INST_BULK_READ = 0x92
INST_BULK_WRITE = 0x93

#: ERR byte: bit 7 is the Alert flag (read Hardware Error Status); bits 0-6 an error number.
ERR_ALERT = 0x80
ERR_RESULT_FAIL = 0x01
ERR_INSTRUCTION = 0x02
ERR_CRC = 0x03
ERR_DATA_RANGE = 0x04
ERR_DATA_LENGTH = 0x05
ERR_DATA_LIMIT = 0x06
ERR_ACCESS = 0x07

ERROR_NAMES = {
    ERR_RESULT_FAIL: "result fail",
    ERR_INSTRUCTION: "instruction error",
    ERR_CRC: "CRC error",
    ERR_DATA_RANGE: "data range error",
    ERR_DATA_LENGTH: "data length error",
    ERR_DATA_LIMIT: "data limit error",
    ERR_ACCESS: "access error",
}


def _crc_table() -> tuple[int, ...]:
    """The MSB-first CRC-16 table for polynomial 0x8005, generated rather than copied."""
    table = []
    for i in range(256):
        crc = i << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
        table.append(crc & 0xFFFF)
    return tuple(table)


CRC_TABLE = _crc_table()


def crc16(data: bytes | bytearray, crc: int = 0) -> int:
    """CRC-16/BUYPASS of ``data`` (check value for b"123456789" is 0xFEE8)."""
    for byte in data:
        crc = ((crc << 8) ^ CRC_TABLE[((crc >> 8) ^ byte) & 0xFF]) & 0xFFFF
    return crc


def stuff(body: bytes) -> bytes:
    """Insert an extra FD after every ``FF FF FD`` in ``body`` (instruction + params)."""
    out = bytearray()
    run = 0  # how many of FF FF FD we have just seen
    for b in body:
        out.append(b)
        if run == 2 and b == 0xFD:
            out.append(0xFD)
            run = 0
        elif b == 0xFF:
            run = 2 if run >= 1 else 1
        else:
            run = 0
    return bytes(out)


def unstuff(body: bytes) -> bytes:
    """Undo :func:`stuff`: drop the FD that follows each ``FF FF FD`` in ``body``."""
    out = bytearray()
    i = 0
    while i < len(body):
        out.append(body[i])
        if (
            len(out) >= 3
            and out[-3:] == b"\xff\xff\xfd"
            and i + 1 < len(body)
            and body[i + 1] == 0xFD
        ):
            i += 1  # skip the stuffed FD
        i += 1
    return bytes(out)


def _frame(dxl_id: int, body: bytes, stuffed: bool) -> bytes:
    if not 0 <= dxl_id <= 0xFE or dxl_id in (0xFD,):
        raise ValueError(f"Dynamixel id {dxl_id} is not 0..252 or 254 (broadcast)")
    body = stuff(body) if stuffed else body
    length = len(body) + 2
    head = HEADER + bytes([dxl_id, length & 0xFF, length >> 8])
    crc = crc16(head + body)
    return head + body + bytes([crc & 0xFF, crc >> 8])


def instruction_packet(dxl_id: int, instruction: int, params: bytes = b"", stuffed=True) -> bytes:
    """Bytes of an instruction packet (stuffed, as the e-manual requires, unless told not to)."""
    return _frame(dxl_id, bytes([instruction]) + bytes(params), stuffed)


def status_packet(dxl_id: int, error: int = 0, params: bytes = b"") -> bytes:
    """Bytes of a status packet, stuffed (the SDK's receiver removes stuffing)."""
    return _frame(dxl_id, bytes([INST_STATUS, error]) + bytes(params), True)


def u16(value: int) -> bytes:
    return int(value).to_bytes(2, "little")


def u32(value: int) -> bytes:
    """Four little-endian bytes; negative values in two's complement (extended position)."""
    return (int(value) & 0xFFFFFFFF).to_bytes(4, "little")


def to_signed(value: int, nbytes: int) -> int:
    """Two's complement of an unsigned register value (the SDK returns reads unsigned)."""
    bits = 8 * nbytes
    value &= (1 << bits) - 1
    return value - (1 << bits) if value & (1 << (bits - 1)) else value


# Convenience builders for the instructions the project uses; names follow the e-manual.
def ping(dxl_id: int) -> bytes:
    return instruction_packet(dxl_id, INST_PING)


def read(dxl_id: int, address: int, length: int) -> bytes:
    return instruction_packet(dxl_id, INST_READ, u16(address) + u16(length))


def write(dxl_id: int, address: int, data: bytes) -> bytes:
    return instruction_packet(dxl_id, INST_WRITE, u16(address) + bytes(data))


def sync_write(address: int, length: int, items: dict[int, bytes]) -> bytes:
    params = bytearray(u16(address) + u16(length))
    for dxl_id, data in items.items():
        if len(data) != length:
            raise ValueError(f"sync write to id {dxl_id}: {len(data)} bytes, expected {length}")
        params += bytes([dxl_id]) + bytes(data)
    return instruction_packet(BROADCAST_ID, INST_SYNC_WRITE, bytes(params))


def sync_read(address: int, length: int, ids: list[int]) -> bytes:
    return instruction_packet(BROADCAST_ID, INST_SYNC_READ, u16(address) + u16(length) + bytes(ids))


@dataclass(frozen=True)
class Packet:
    """A parsed packet. For status packets ``instruction`` is 0x55 and ``error`` is set."""

    dxl_id: int
    instruction: int
    params: bytes
    error: int | None = None
    raw: bytes = b""

    @property
    def is_status(self) -> bool:
        return self.instruction == INST_STATUS


class CrcMismatch(ValueError):
    """A complete packet arrived with a wrong CRC (discarded, like a servo would)."""

    def __init__(self, raw: bytes) -> None:
        super().__init__(f"CRC mismatch in packet {raw.hex(' ')}")
        self.raw = raw


class PacketParser:
    """Incremental parser for a byte stream, by length.

    ``feed`` bytes, then iterate :meth:`packets`. Garbage before a header is skipped; once a
    header is found the packet is taken whole by its LEN field, so an unstuffed ``FF FF FD`` in
    the body (the SDK's quirk) does not cut it short. A packet with a bad CRC is reported as a
    :class:`CrcMismatch` item and dropped.
    """

    def __init__(self) -> None:
        self._buf = bytearray()

    def feed(self, data: bytes) -> None:
        self._buf += data

    def packets(self) -> list[Packet | CrcMismatch]:
        out: list[Packet | CrcMismatch] = []
        while True:
            start = self._buf.find(HEADER)
            if start < 0:
                # keep a possible partial header at the end
                keep = 3 if len(self._buf) >= 3 else len(self._buf)
                del self._buf[: len(self._buf) - keep]
                return out
            del self._buf[:start]
            if len(self._buf) < 7:
                return out
            length = self._buf[5] | (self._buf[6] << 8)
            total = 7 + length
            if length < 3:
                del self._buf[:4]
                continue
            if len(self._buf) < total:
                return out
            raw = bytes(self._buf[:total])
            del self._buf[:total]
            crc = raw[-2] | (raw[-1] << 8)
            if crc16(raw[:-2]) != crc:
                out.append(CrcMismatch(raw))
                continue
            out.append(decode(raw))


def decode(raw: bytes) -> Packet:
    """Decode one whole, CRC-checked packet; stuffing is removed from the body."""
    if raw[:4] != HEADER:
        raise ValueError(f"not a Protocol 2.0 packet: {raw[:4].hex(' ')}")
    body = unstuff(raw[7:-2])
    instruction = body[0]
    if instruction == INST_STATUS:
        return Packet(raw[4], instruction, bytes(body[2:]), error=body[1], raw=raw)
    return Packet(raw[4], instruction, bytes(body[1:]), raw=raw)


def describe_error(error: int) -> str:
    """Human-readable ERR byte, e.g. 'data limit error + hardware alert'."""
    parts = []
    number = error & 0x7F
    if number:
        parts.append(ERROR_NAMES.get(number, f"unknown error {number}"))
    if error & ERR_ALERT:
        parts.append("hardware alert (read Hardware Error Status)")
    return " + ".join(parts) if parts else "ok"
