"""The ``binary`` profile: fixed 7-byte commands, answered by a one-byte acknowledgement.

Shaped after domes with a binary link and a single ack byte (e.g. a header byte followed by
LED bytes, acknowledged by ``0x01``). A bare constant ack cannot tell a late reply from the
current one, so this profile spends the ack byte on the sequence number instead::

    command:  A5 op seq idx_hi idx_lo level xor        xor = XOR of the first 6 bytes
    ack:      seq                  0x01..0x7F           command ``seq`` done
    nak:      0x80 | code          0x81..0xBF           refused (code 1..63, shared table)
    banner:   FF 52 44 59          "\\xffRDY"            the board (re)booted

Ops: 01 hello, 02 light (idx, level), 03 all off, 04 shutter (idx field = pulse ms), 05 query.
The hello ack carries a payload ``seq major minor count_hi count_lo fw_code xor`` and the query
ack ``seq idx_hi idx_lo level xor`` (idx FFFF: all off), each closed by an XOR of the bytes
before it. The light ack carries no echo: when that matters, the rig policy confirms with a query.
"""

from __future__ import annotations

from collections.abc import Callable

from rti_rig.drivers.led_dome.codec_base import xor_checksum
from rti_rig.drivers.led_dome.messages import (
    ERROR_CODES,
    Ack,
    AllOff,
    Banner,
    Command,
    DomeIdentity,
    Garbled,
    Hello,
    Light,
    LitState,
    Nak,
    Query,
    Reply,
    Shutter,
)

SEQ_MAX = 0x7F
BANNER = b"\xffRDY"
OP_HELLO, OP_LIGHT, OP_ALL_OFF, OP_SHUTTER, OP_QUERY = 1, 2, 3, 4, 5
NO_LED = 0xFFFF
PACKET_LEN = 7


class BinaryCodec:
    """Codec of the ``binary`` profile (see the module docstring)."""

    profile = "binary"
    has_sequence = True
    has_watchdog = False
    has_level = True

    def __init__(self, start_byte: int = 0xA5, index_base: int = 0) -> None:
        if not 0 <= start_byte <= 0xFF:
            raise ValueError(f"start_byte {start_byte} is not a byte")
        self.start_byte = start_byte
        self.index_base = index_base

    def next_seq(self, seq: int) -> int:
        return seq + 1 if 1 <= seq < SEQ_MAX else 1

    # ------------------------------------------------------------ host side

    def encode_command(self, seq: int, cmd: Command) -> bytes:
        if not 1 <= seq <= SEQ_MAX:
            raise ValueError(f"binary sequence numbers run 1..127, not {seq}")
        arg, level = 0, 0
        if isinstance(cmd, Hello):
            op = OP_HELLO
        elif isinstance(cmd, Light):
            op, arg, level = OP_LIGHT, cmd.index + self.index_base, cmd.level
        elif isinstance(cmd, AllOff):
            op = OP_ALL_OFF
        elif isinstance(cmd, Shutter):
            op, arg = OP_SHUTTER, cmd.pulse_ms
        elif isinstance(cmd, Query):
            op = OP_QUERY
        else:
            raise TypeError(f"not a command: {cmd!r}")
        if not 0 <= arg <= 0xFFFE or not 0 <= level <= 0xFF:
            raise ValueError(f"argument out of range for the binary profile: {cmd!r}")
        body = bytes([self.start_byte, op, seq, arg >> 8, arg & 0xFF, level])
        return body + bytes([xor_checksum(body)])

    def decode_reply(self, buf: bytes, pending: Command | None) -> tuple[Reply | None, int]:
        if not buf:
            return None, 0
        first = buf[0]
        if first == BANNER[0]:
            if len(buf) < len(BANNER):
                return None, 0
            if buf[: len(BANNER)] == BANNER:
                return Banner(None), len(BANNER)
            return Garbled(bytes(buf[:1]), "0xFF not followed by RDY"), 1
        if 0x80 <= first <= 0xBF:
            code = first & 0x3F
            if code not in ERROR_CODES:
                return Garbled(bytes(buf[:1]), f"unknown error byte 0x{first:02X}"), 1
            return Nak(None, code), 1
        if not 1 <= first <= SEQ_MAX:
            return Garbled(bytes(buf[:1]), f"byte 0x{first:02X} is no acknowledgement"), 1
        if isinstance(pending, Hello):
            return self._payload(buf, 7, _identity)
        if isinstance(pending, Query):
            return self._payload(buf, 5, self._lit_state)
        return Ack(first), 1

    def _lit_state(self, chunk: bytes) -> LitState:
        idx = (chunk[1] << 8) | chunk[2]
        return LitState(None if idx == NO_LED else idx - self.index_base, chunk[3])

    @staticmethod
    def _payload(
        buf: bytes, size: int, parse: Callable[[bytes], DomeIdentity | LitState]
    ) -> tuple[Reply | None, int]:
        if len(buf) < size:
            return None, 0
        chunk = bytes(buf[:size])
        if xor_checksum(chunk[:-1]) != chunk[-1]:
            return Garbled(chunk, "payload checksum mismatch"), size
        return Ack(chunk[0], parse(chunk)), size


def _identity(chunk: bytes) -> DomeIdentity:
    return DomeIdentity(
        firmware_id=f"binary-0x{chunk[5]:02X}",
        version=f"{chunk[1]}.{chunk[2]}",
        led_count=(chunk[3] << 8) | chunk[4],
    )
