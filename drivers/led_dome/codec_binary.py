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
    ERR_BAD_CHECKSUM,
    ERR_UNKNOWN_COMMAND,
    ERROR_CODES,
    Ack,
    AllOff,
    BadRequest,
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

    # ------------------------------------------------------------ firmware side

    def decode_command(
        self, buf: bytes
    ) -> tuple[tuple[int | None, Command] | BadRequest | None, int]:
        start = buf.find(bytes([self.start_byte]))
        if start < 0:
            return None, len(buf)  # line noise: a real firmware skips it silently
        if start > 0:
            return None, start
        if len(buf) < PACKET_LEN:
            return None, 0
        pkt = bytes(buf[:PACKET_LEN])
        if xor_checksum(pkt[:-1]) != pkt[-1]:
            return BadRequest(pkt, None, ERR_BAD_CHECKSUM, "checksum mismatch"), PACKET_LEN
        op, seq, arg, level = pkt[1], pkt[2], (pkt[3] << 8) | pkt[4], pkt[5]
        cmd: Command
        if op == OP_HELLO:
            cmd = Hello()
        elif op == OP_LIGHT:
            if arg < self.index_base:
                return BadRequest(pkt, seq, 2, "LED below index base"), PACKET_LEN
            cmd = Light(arg - self.index_base, level)
        elif op == OP_ALL_OFF:
            cmd = AllOff()
        elif op == OP_SHUTTER:
            cmd = Shutter(arg)
        elif op == OP_QUERY:
            cmd = Query()
        else:
            return BadRequest(pkt, seq, ERR_UNKNOWN_COMMAND, f"op 0x{op:02X}"), PACKET_LEN
        return (seq, cmd), PACKET_LEN

    def encode_reply(self, reply: Reply, cmd: Command | None) -> bytes:
        if isinstance(reply, Banner):
            return BANNER
        if isinstance(reply, Nak):
            if not 1 <= reply.code <= 0x3F:
                raise ValueError(f"error code {reply.code} does not fit the binary nak")
            return bytes([0x80 | reply.code])
        if isinstance(reply, Ack):
            seq = reply.seq or 0
            echo = reply.echo
            if isinstance(echo, DomeIdentity):
                major, _, minor = echo.version.partition(".")
                code = _firmware_code(echo.firmware_id)
                n = echo.led_count
                body = bytes(
                    [seq, int(major), int(minor.split(".")[0] or 0), n >> 8, n & 0xFF, code]
                )
                return body + bytes([xor_checksum(body)])
            if isinstance(echo, LitState):
                idx = NO_LED if echo.index is None else echo.index + self.index_base
                body = bytes([seq, idx >> 8, idx & 0xFF, echo.level])
                return body + bytes([xor_checksum(body)])
            return bytes([seq])
        raise TypeError(f"cannot encode {reply!r}")

    def encode_banner(self, identity: DomeIdentity) -> bytes:
        return BANNER


def _firmware_code(firmware_id: str) -> int:
    """Binary firmwares identify themselves by one byte; ids look like ``binary-0x2A``."""
    _, _, tail = firmware_id.rpartition("0x")
    try:
        return int(tail, 16) & 0xFF
    except ValueError:
        return 0


def _identity(chunk: bytes) -> DomeIdentity:
    return DomeIdentity(
        firmware_id=f"binary-0x{chunk[5]:02X}",
        version=f"{chunk[1]}.{chunk[2]}",
        led_count=(chunk[3] << 8) | chunk[4],
    )
