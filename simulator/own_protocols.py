"""The firmware side of rti-rig's own dome protocols, written from docs/protocols/led-dome.md alone.

Why a reading of its own: the driver's codecs (``rti_rig.drivers.led_dome.codec_*``) had
encoded and decoded both sides of the wire (they are the host's side alone now), and an emulator
built on them shared every one of their bugs, invisible to any test that drives the real driver
against it. This module parses command
bytes and writes reply bytes as a firmware author would, from the page's tables and examples
(the byte-exact fixtures it names are the normative examples), and it imports nothing of the
driver's wire format: ``tests/architecture`` holds an import-linter contract that forbids it.

Each profile reads one command from the front of a buffer (:meth:`OwnCodec.decode`) and
writes the board's answers (:meth:`OwnCodec.ok`, :meth:`OwnCodec.err`, :meth:`OwnCodec.banner`).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import ClassVar, Protocol

# Error codes of the page's table "Error codes (all profiles)".
UNKNOWN_COMMAND = 1
BAD_ARGUMENT = 2
LED_OUT_OF_RANGE = 3
LED_FAULT = 4
BAD_CHECKSUM = 6

#: Longest command a board buffers while it waits for its end: a line or frame that grows past
#: it is noise (a wrong baud rate), dropped rather than kept forever.
MAX_COMMAND = 128


class Verb(StrEnum):
    HELLO = "hello"
    LIGHT = "light"
    ALL_OFF = "all_off"
    SHUTTER = "shutter"
    QUERY = "query"


@dataclass(frozen=True)
class Request:
    """A command as the firmware read it; ``index`` is 0-based (after ``index_base``)."""

    verb: Verb
    seq: int | None
    index: int = 0
    level: int = 0
    max_on_ms: int | None = None
    pulse_ms: int = 0


@dataclass(frozen=True)
class Refused:
    """Bytes that are no valid command: answered with error ``code`` (``seq`` if readable)."""

    raw: bytes
    seq: int | None
    code: int
    text: str


@dataclass(frozen=True)
class BoardFacts:
    """What the board tells of itself in its banner and handshake reply."""

    firmware_id: str
    version: str
    led_count: int
    #: The binary profile's hello reply carries a one-byte firmware code, not a name.
    firmware_code: int = 0x2A


class OwnCodec(Protocol):
    """One profile's bytes, the firmware's side."""

    profile: str

    def decode(self, buf: bytes) -> tuple[Request | Refused | None, int]:
        """One command from the front of ``buf``: (command or refusal, bytes consumed);
        ``(None, n)``: drop ``n`` bytes of noise and wait for more."""
        ...

    def ok(self, req: Request, facts: BoardFacts, lit: tuple[int, int] | None) -> bytes:
        """The acknowledgement of ``req``, echoing what was executed (``lit``: a query's state)."""
        ...

    def err(self, seq: int | None, code: int, text: str) -> bytes: ...

    def banner(self, facts: BoardFacts) -> bytes: ...


def _xor(data: bytes) -> int:
    value = 0
    for b in data:
        value ^= b
    return value


def _int(word: bytes | str) -> int | None:
    """A decimal number as the page writes them (optional minus, digits only), else None."""
    text = word.decode("ascii", "replace") if isinstance(word, bytes) else word
    body = text[1:] if text.startswith("-") else text
    return int(text) if body.isdigit() and body.isascii() else None


# ------------------------------------------------------------------------------ default


@dataclass
class DefaultProfile:
    """``<seq> <verb> [args]*HH\\n``; replies ``OK <seq> <verb> <echo>*HH`` or ``ERR``."""

    checksum: bool = True
    #: What ends each line the board sends: LF, or CR LF as ``Serial.println`` does (the page:
    #: "replies may end in CR LF").
    line_end: bytes = b"\n"
    profile: str = "default"

    def decode(self, buf: bytes) -> tuple[Request | Refused | None, int]:
        end = buf.find(b"\n")
        if end < 0:
            return (None, len(buf)) if len(buf) > MAX_COMMAND else (None, 0)
        raw = buf[: end + 1]
        line = raw[:-1].rstrip(b"\r")
        if not line.strip():
            return None, len(raw)  # an empty line is no command
        if self.checksum:
            body, star, check = line.rpartition(b"*")
            if (
                not star
                or len(check) != 2
                or any(c not in b"0123456789ABCDEF" for c in check)
                or int(check, 16) != _xor(body)
            ):
                return Refused(raw, None, BAD_CHECKSUM, "checksum mismatch"), len(raw)
            line = body
        words = line.split(b" ")
        seq = _int(words[0])
        if seq is None or not 1 <= seq <= 9999:
            return Refused(raw, None, BAD_ARGUMENT, "bad sequence number"), len(raw)
        verb, args = (words[1] if len(words) > 1 else b""), words[2:]
        nums = [_int(a) for a in args]
        if any(n is None or n < 0 for n in nums):
            return Refused(raw, seq, BAD_ARGUMENT, "bad argument"), len(raw)
        values = [n for n in nums if n is not None]
        shapes = {b"ID": (0,), b"X": (0,), b"Q": (0,), b"S": (1,), b"L": (2, 3)}
        if verb not in shapes:
            return Refused(raw, seq, UNKNOWN_COMMAND, "unknown command"), len(raw)
        if len(values) not in shapes[verb]:
            return Refused(raw, seq, BAD_ARGUMENT, "wrong argument count"), len(raw)
        if verb == b"ID":
            return Request(Verb.HELLO, seq), len(raw)
        if verb == b"X":
            return Request(Verb.ALL_OFF, seq), len(raw)
        if verb == b"Q":
            return Request(Verb.QUERY, seq), len(raw)
        if verb == b"S":
            return Request(Verb.SHUTTER, seq, pulse_ms=values[0]), len(raw)
        watchdog = values[2] if len(values) == 3 else None
        return Request(Verb.LIGHT, seq, values[0], values[1], watchdog), len(raw)

    def ok(self, req: Request, facts: BoardFacts, lit: tuple[int, int] | None) -> bytes:
        words: list[object] = ["OK", req.seq]
        if req.verb is Verb.HELLO:
            words += ["ID", facts.firmware_id, facts.version, facts.led_count]
        elif req.verb is Verb.LIGHT:
            words += ["L", req.index, req.level]
            words += [] if req.max_on_ms is None else [req.max_on_ms]
        elif req.verb is Verb.ALL_OFF:
            words += ["X"]
        elif req.verb is Verb.SHUTTER:
            words += ["S", req.pulse_ms]
        else:
            words += ["Q", -1, 0] if lit is None else ["Q", lit[0], lit[1]]
        return self._line(" ".join(str(w) for w in words))

    def err(self, seq: int | None, code: int, text: str) -> bytes:
        return self._line(f"ERR {seq or 0} {code} {'_'.join(text.split()) or '-'}")

    def banner(self, facts: BoardFacts) -> bytes:
        return self._line(f"READY {facts.firmware_id} {facts.version} {facts.led_count}")

    def _line(self, body: str) -> bytes:
        data = body.encode("ascii", "replace")
        if self.checksum:
            data += b"*%02X" % _xor(data)
        return data + self.line_end


# ------------------------------------------------------------------------------ framed


@dataclass
class FramedProfile:
    """``<code,seq,args...>``; replies ``<OK,seq,code,args...>``, ``<ERR,seq,errcode,text>``,
    banner ``<READY,id,version,count>``, with the options of ``[dome.serial.framed]``."""

    start: str = "<"
    end: str = ">"
    separator: str = ","
    codes: dict[str, str] | None = None  # verb name -> code; None: 9/3/0/6/8
    index_base: int = 0
    send_level: bool = True
    sequence: bool = True
    ok_word: str = "OK"
    err_word: str = "ERR"
    ready_word: str = "READY"
    full_level: int = 255
    profile: str = "framed"

    def __post_init__(self) -> None:
        given = self.codes or {}
        defaults = {"hello": "9", "light": "3", "all_off": "0", "shutter": "6", "query": "8"}
        self._code_of = {Verb(k): given.get(k, v) for k, v in defaults.items()}
        self._verb_of = {code: verb for verb, code in self._code_of.items()}

    def decode(self, buf: bytes) -> tuple[Request | Refused | None, int]:
        start, end = self.start.encode(), self.end.encode()
        at = buf.find(start)
        if at < 0:
            return None, len(buf)  # bytes outside a frame (line endings, noise) are skipped
        if at > 0:
            return None, at
        stop = buf.find(end, 1)
        restart = buf.find(start, 1)
        if restart > 0 and (stop < 0 or restart < stop):
            return None, restart  # a frame cut short by a new start: the new one counts
        if stop < 0:
            return (None, len(buf)) if len(buf) > MAX_COMMAND else (None, 0)
        raw = buf[: stop + 1]
        fields = raw[1:-1].decode("ascii", "replace").split(self.separator)
        verb = self._verb_of.get(fields[0])
        seq: int | None = None
        if self.sequence:
            seq = _int(fields[1]) if len(fields) > 1 else None
            if seq is None or seq < 0:
                return Refused(raw, None, BAD_ARGUMENT, "bad sequence number"), len(raw)
            args = fields[2:]
        else:
            args = fields[1:]
        if verb is None:
            return Refused(raw, seq, UNKNOWN_COMMAND, "unknown command"), len(raw)
        nums = [_int(a) for a in args]
        wanted = {Verb.LIGHT: 2 if self.send_level else 1, Verb.SHUTTER: 1}.get(verb, 0)
        if len(nums) != wanted or any(n is None or n < 0 for n in nums):
            return Refused(raw, seq, BAD_ARGUMENT, "bad argument"), len(raw)
        values = [n for n in nums if n is not None]
        if verb is Verb.LIGHT:
            index = values[0] - self.index_base
            if index < 0:
                return Refused(raw, seq, LED_OUT_OF_RANGE, f"LED {values[0]}"), len(raw)
            level = values[1] if self.send_level else self.full_level
            return Request(verb, seq, index, level), len(raw)
        if verb is Verb.SHUTTER:
            return Request(verb, seq, pulse_ms=values[0]), len(raw)
        return Request(verb, seq), len(raw)

    def ok(self, req: Request, facts: BoardFacts, lit: tuple[int, int] | None) -> bytes:
        fields: list[object] = [self.ok_word, *self._seq(req.seq), self._code_of[req.verb]]
        if req.verb is Verb.HELLO:
            fields += [facts.firmware_id, facts.version, facts.led_count]
        elif req.verb is Verb.LIGHT:
            fields += [req.index + self.index_base]
            fields += [req.level] if self.send_level else []
        elif req.verb is Verb.SHUTTER:
            fields += [req.pulse_ms]
        elif req.verb is Verb.QUERY:
            fields += [-1, 0] if lit is None else [lit[0] + self.index_base, lit[1]]
        return self._frame(fields)

    def err(self, seq: int | None, code: int, text: str) -> bytes:
        for mark in (self.start, self.end, self.separator):
            text = text.replace(mark, " ")
        return self._frame([self.err_word, *self._seq(seq), code, text])

    def banner(self, facts: BoardFacts) -> bytes:
        return self._frame([self.ready_word, facts.firmware_id, facts.version, facts.led_count])

    def _seq(self, seq: int | None) -> list[object]:
        return [seq or 0] if self.sequence else []

    def _frame(self, fields: list[object]) -> bytes:
        body = self.separator.join(str(f) for f in fields)
        return (self.start + body + self.end).encode("ascii", "replace")


# ------------------------------------------------------------------------------ binary


@dataclass
class BinaryProfile:
    """``A5 op seq idx_hi idx_lo level xor``; ack ``seq``, nak ``0x80 | code``, banner
    ``FF 52 44 59``; hello and query acks carry a payload ending in its XOR."""

    start_byte: int = 0xA5
    index_base: int = 0
    profile: str = "binary"

    _OPS: ClassVar[dict[int, Verb]] = {
        1: Verb.HELLO,
        2: Verb.LIGHT,
        3: Verb.ALL_OFF,
        4: Verb.SHUTTER,
        5: Verb.QUERY,
    }

    def decode(self, buf: bytes) -> tuple[Request | Refused | None, int]:
        at = buf.find(bytes([self.start_byte]))
        if at < 0:
            return None, len(buf)
        if at > 0:
            return None, at
        if len(buf) < 7:
            return None, 0
        raw = buf[:7]
        if _xor(raw[:6]) != raw[6]:
            return Refused(raw, None, BAD_CHECKSUM, "checksum mismatch"), 7
        op, seq, idx, level = raw[1], raw[2], raw[3] << 8 | raw[4], raw[5]
        if not 1 <= seq <= 0x7F:
            return Refused(raw, None, BAD_ARGUMENT, "bad sequence number"), 7
        verb = self._OPS.get(op)
        if verb is None:
            return Refused(raw, seq, UNKNOWN_COMMAND, "unknown op"), 7
        if verb is Verb.LIGHT:
            if idx < self.index_base:
                return Refused(raw, seq, LED_OUT_OF_RANGE, f"LED {idx}"), 7
            return Request(verb, seq, idx - self.index_base, level), 7
        if verb is Verb.SHUTTER:
            return Request(verb, seq, pulse_ms=idx), 7
        return Request(verb, seq), 7

    def ok(self, req: Request, facts: BoardFacts, lit: tuple[int, int] | None) -> bytes:
        seq = req.seq or 0
        if req.verb is Verb.HELLO:
            parts = [*facts.version.split("."), "0", "0"][:2]
            major, minor = (_int(p) or 0 for p in parts)
            count = facts.led_count
            body = bytes([seq, major & 0xFF, minor & 0xFF, count >> 8 & 0xFF, count & 0xFF])
            body += bytes([facts.firmware_code & 0xFF])
            return body + bytes([_xor(body)])
        if req.verb is Verb.QUERY:
            idx = 0xFFFF if lit is None else lit[0] + self.index_base
            level = 0 if lit is None else lit[1]
            body = bytes([seq, idx >> 8 & 0xFF, idx & 0xFF, level & 0xFF])
            return body + bytes([_xor(body)])
        return bytes([seq])

    def err(self, seq: int | None, code: int, text: str) -> bytes:
        return bytes([0x80 | (code & 0x3F)])

    def banner(self, facts: BoardFacts) -> bytes:
        return b"\xffRDY"
