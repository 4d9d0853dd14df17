"""The default profile: line-based ASCII with sequence numbers, echoes and an XOR checksum.

Specified in ``docs/protocols/led-dome.md``. One command per line, one reply per command::

    host:  7 L 12 200 5000*4F\\n        light LED 12 at level 200, firmware watchdog 5000 ms
    dome:  OK 7 L 12 200 5000*6B\\n     done, echoing what it executed

Why each part: the sequence number lets the host recognise a late reply to an earlier command
instead of taking it for the current one; the echo lets it check the firmware lit the LED it
asked for (a garbled index cannot pass silently); the checksum (XOR of the bytes before ``*``,
two upper-case hex digits) catches damaged lines in both directions; the boot banner
(``READY <id> <version> <count>``) tells the host when the board is ready after the auto-reset
on port open, and reveals a reset in the middle of a session.
"""

from __future__ import annotations

from rti_rig.drivers.led_dome.codec_base import xor_checksum
from rti_rig.drivers.led_dome.messages import (
    ERR_BAD_ARGUMENT,
    ERR_BAD_CHECKSUM,
    ERR_UNKNOWN_COMMAND,
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

SEQ_MAX = 9999
#: A line longer than this without a terminator is noise, not a reply being received.
MAX_LINE = 200


class DefaultCodec:
    """Codec of the ``default`` profile (see the module docstring)."""

    profile = "default"
    has_sequence = True
    has_watchdog = True
    has_level = True

    def __init__(self, checksum: bool = True) -> None:
        self.checksum = checksum

    def next_seq(self, seq: int) -> int:
        return seq + 1 if 1 <= seq < SEQ_MAX else 1

    # ------------------------------------------------------------ framing

    def _line(self, body: str) -> bytes:
        raw = body.encode("ascii")
        if self.checksum:
            raw += b"*%02X" % xor_checksum(raw)
        return raw + b"\n"

    def _take_line(self, buf: bytes) -> tuple[bytes | None, int, str | None]:
        """(body without checksum, consumed, error) for the first line in ``buf``."""
        end = buf.find(b"\n")
        if end < 0:
            if len(buf) > MAX_LINE:
                return None, len(buf), "no line terminator within 200 bytes"
            return None, 0, None
        line = buf[:end].rstrip(b"\r")
        consumed = end + 1
        if not line:
            # a stray line ending (an Arduino's Serial.println() after its banner, a CR LF
            # host line ending echoed back): no reply, skipped; a line of anything else is
            # still read, and refused if garbled
            return None, consumed, None
        if self.checksum:
            star = line.rfind(b"*")
            if star < 0 or len(line) - star != 3:
                return None, consumed, "missing checksum"
            body, digits = line[:star], line[star + 1 :]
            if any(d not in b"0123456789ABCDEF" for d in digits):
                return None, consumed, "unreadable checksum (two upper-case hex digits)"
            expected = int(digits.decode("ascii"), 16)
            if xor_checksum(body) != expected:
                return None, consumed, "checksum mismatch"
            line = body
        try:
            line.decode("ascii")
        except UnicodeDecodeError:
            return None, consumed, "non-ASCII bytes"
        return line, consumed, None

    # ------------------------------------------------------------ host side

    def encode_command(self, seq: int, cmd: Command) -> bytes:
        return self._line(f"{seq} {_command_body(cmd)}")

    def decode_reply(self, buf: bytes, pending: Command | None) -> tuple[Reply | None, int]:
        line, consumed, error = self._take_line(buf)
        if error is not None:
            return Garbled(bytes(buf[:consumed]), error), consumed
        if line is None:
            return None, consumed  # more bytes needed, or a blank line dropped
        tokens = line.decode("ascii").split()
        try:
            return _parse_reply(tokens), consumed
        except (ValueError, IndexError) as exc:
            return Garbled(bytes(buf[:consumed]), f"unreadable reply ({exc})"), consumed

    # ------------------------------------------------------------ firmware side

    def decode_command(
        self, buf: bytes
    ) -> tuple[tuple[int | None, Command] | BadRequest | None, int]:
        line, consumed, error = self._take_line(buf)
        if error is not None:
            return BadRequest(bytes(buf[:consumed]), None, ERR_BAD_CHECKSUM, error), consumed
        if line is None:
            return None, consumed
        tokens = line.decode("ascii").split()
        seq: int | None = None
        try:
            seq = int(tokens[0])
            return (seq, _parse_command(tokens[1:])), consumed
        except _UnknownVerb as exc:
            return BadRequest(line, seq, ERR_UNKNOWN_COMMAND, str(exc)), consumed
        except (ValueError, IndexError) as exc:
            return BadRequest(line, seq, ERR_BAD_ARGUMENT, f"bad arguments ({exc})"), consumed

    def encode_reply(self, reply: Reply, cmd: Command | None) -> bytes:
        if isinstance(reply, Ack):
            echo = reply.echo
            if isinstance(echo, DomeIdentity):
                tail = f"ID {echo.firmware_id} {echo.version} {echo.led_count}"
            elif isinstance(echo, LitState):
                idx = -1 if echo.index is None else echo.index
                tail = f"Q {idx} {echo.level}"
            elif echo is None:
                raise ValueError("the default profile always echoes the executed command")
            else:
                tail = _command_body(echo)
            return self._line(f"OK {reply.seq} {tail}")
        if isinstance(reply, Nak):
            seq = 0 if reply.seq is None else reply.seq
            text = "_".join(reply.text.split()) or "-"
            return self._line(f"ERR {seq} {reply.code} {text}")
        if isinstance(reply, Banner):
            if reply.identity is None:
                return self._line("READY")
            return self.encode_banner(reply.identity)
        raise TypeError(f"cannot encode {reply!r}")

    def encode_banner(self, identity: DomeIdentity) -> bytes:
        return self._line(f"READY {identity.firmware_id} {identity.version} {identity.led_count}")


class _UnknownVerb(ValueError):
    pass


def _command_body(cmd: Command | DomeIdentity | LitState) -> str:
    if isinstance(cmd, Hello):
        return "ID"
    if isinstance(cmd, Light):
        tail = "" if cmd.max_on_ms is None else f" {cmd.max_on_ms}"
        return f"L {cmd.index} {cmd.level}{tail}"
    if isinstance(cmd, AllOff):
        return "X"
    if isinstance(cmd, Shutter):
        return f"S {cmd.pulse_ms}"
    if isinstance(cmd, Query):
        return "Q"
    raise TypeError(f"not a command: {cmd!r}")


def _nonneg(token: str) -> int:
    value = int(token)
    if value < 0:
        raise ValueError(f"negative value {value}")
    return value


def _parse_command(tokens: list[str]) -> Command:
    verb, args = tokens[0], tokens[1:]
    if verb == "ID" and not args:
        return Hello()
    if verb == "L" and len(args) in (2, 3):
        max_on = _nonneg(args[2]) if len(args) == 3 else None
        return Light(_nonneg(args[0]), _nonneg(args[1]), max_on)
    if verb == "X" and not args:
        return AllOff()
    if verb == "S" and len(args) == 1:
        return Shutter(_nonneg(args[0]))
    if verb == "Q" and not args:
        return Query()
    if verb in {"ID", "L", "X", "S", "Q"}:
        raise ValueError(f"wrong number of arguments for {verb}")
    raise _UnknownVerb(f"unknown verb {verb!r}")


def _parse_reply(tokens: list[str]) -> Reply:
    head = tokens[0]
    if head == "READY":
        if len(tokens) == 1:
            return Banner(None)
        return Banner(DomeIdentity(tokens[1], tokens[2], int(tokens[3])))
    if head == "ERR":
        return Nak(int(tokens[1]) or None, int(tokens[2]), " ".join(tokens[3:]).replace("_", " "))
    if head != "OK":
        raise ValueError(f"unknown reply {head!r}")
    seq = int(tokens[1])
    verb, args = tokens[2], tokens[3:]
    if verb == "ID":
        return Ack(seq, DomeIdentity(args[0], args[1], int(args[2])))
    if verb == "Q":
        idx = int(args[0])
        return Ack(seq, LitState(None if idx < 0 else idx, int(args[1])))
    return Ack(seq, _parse_command([verb, *args]))
