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

from rti_rig.drivers.led_dome.codec_base import decimal, reply_seq, xor_checksum
from rti_rig.drivers.led_dome.messages import (
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
        try:
            return _parse_reply(line.decode("ascii")), consumed
        except (ValueError, IndexError) as exc:
            return Garbled(bytes(buf[:consumed]), f"unreadable reply ({exc})"), consumed


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


def _parse_command(tokens: list[str]) -> Command:
    """The command a reply echoes, its arguments exactly as many as the verb takes."""
    verb, args = tokens[0], tokens[1:]
    if verb == "ID" and not args:
        return Hello()
    if verb == "L" and len(args) in (2, 3):
        max_on = decimal(args[2]) if len(args) == 3 else None
        return Light(decimal(args[0]), decimal(args[1]), max_on)
    if verb == "X" and not args:
        return AllOff()
    if verb == "S" and len(args) == 1:
        return Shutter(decimal(args[0]))
    if verb == "Q" and not args:
        return Query()
    if verb in {"ID", "L", "X", "S", "Q"}:
        raise ValueError(f"wrong number of arguments for {verb}")
    raise ValueError(f"unknown verb {verb!r}")


def _parse_reply(text: str) -> Reply:
    """One reply line (its checksum, if any, removed), read as the page writes it: fields
    separated by one space, each field's count and numbers exact; anything else is garbled.

    Why: the line had been split on any run of whitespace and its numbers read by ``int``,
    extra fields ignored, so without a checksum a damaged ``OK 10 Q 12 200`` (``200`` ->
    ``20 ``) read as level 20 lit, and ``... 48`` -> ``4 `` as a board of 4 LEDs."""
    tokens = text.split(" ")
    if "" in tokens:
        raise ValueError("fields not separated by one space")
    head = tokens[0]
    if head == "READY":
        if len(tokens) == 1:
            return Banner(None)
        if len(tokens) != 4:
            raise ValueError("a banner carries an id, a version and a count")
        return Banner(DomeIdentity(tokens[1], tokens[2], decimal(tokens[3])))
    if head == "ERR":
        if len(tokens) != 4:
            raise ValueError("an error carries a sequence number, a code and one word")
        seq = reply_seq(tokens[1], SEQ_MAX, error=True)
        return Nak(seq or None, decimal(tokens[2]), tokens[3].replace("_", " "))
    if head != "OK":
        raise ValueError(f"unknown reply {head!r}")
    seq = reply_seq(tokens[1], SEQ_MAX)
    verb, args = tokens[2], tokens[3:]
    if verb == "ID":
        if len(args) != 3:
            raise ValueError("an identity carries a name, a version and a count")
        return Ack(seq, DomeIdentity(args[0], args[1], decimal(args[2])))
    if verb == "Q":
        if len(args) != 2:
            raise ValueError("a lit state carries an index and a level")
        idx = decimal(args[0], signed=True)
        if idx < -1:
            raise ValueError(f"LED index {idx}")
        return Ack(seq, LitState(None if idx < 0 else idx, decimal(args[1])))
    return Ack(seq, _parse_command([verb, *args]))
