"""The ``framed`` profile: ``<cmd,arg,...>`` frames between start and end markers.

Shaped after the Arduino "start/end marker" sketches common on hobby domes (for example
``<3,N>`` to light LED N, ``<0>`` all off, ``<6>`` shutter). Everything that differs between
such firmwares is a profile option in the rig config, not Python: the markers, the separator,
the code of each command, 0- or 1-based LED numbers, whether an intensity is sent, whether a
sequence number follows the command code, and the reply words.

Frames, with the default options (``seq`` present)::

    host:  <3,7,12,200>            light LED 12 at level 200 (command 7)
    dome:  <OK,7,3,12,200>         done, echoing what it executed
    dome:  <ERR,7,4,LED fault>     refused, error code 4
    dome:  <READY,NABDOME,1.0,48>  boot banner

Without sequence numbers (``sequence = false``) a late reply can only be told apart by its echo,
which is weaker: the driver then drains stale input before every command and checks echoes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from rti_rig.drivers.led_dome.codec_base import decimal, reply_seq
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
MAX_FRAME = 200


@dataclass(frozen=True)
class FramedSpec:
    """Every knob of the framed profile (mirrors ``FramedOptions`` in the settings)."""

    start: str = "<"
    end: str = ">"
    separator: str = ","
    line_ending: str = ""
    codes: dict[str, str] = field(
        default_factory=lambda: {
            "hello": "9",
            "light": "3",
            "all_off": "0",
            "shutter": "6",
            "query": "8",
        }
    )
    index_base: int = 0
    send_level: bool = True
    sequence: bool = True
    ok_word: str = "OK"
    err_word: str = "ERR"
    ready_word: str = "READY"
    full_level: int = 255


class FramedCodec:
    """Codec of the ``framed`` profile (see the module docstring)."""

    profile = "framed"
    has_watchdog = False

    def __init__(self, spec: FramedSpec | None = None) -> None:
        self.spec = spec or FramedSpec()
        self.has_sequence = self.spec.sequence
        self.has_level = self.spec.send_level
        self._verb_of_code = {code: verb for verb, code in self.spec.codes.items()}

    def next_seq(self, seq: int) -> int:
        return seq + 1 if 1 <= seq < SEQ_MAX else 1

    # ------------------------------------------------------------ framing

    def _frame(self, fields: list[str]) -> bytes:
        s = self.spec
        return (s.start + s.separator.join(fields) + s.end + s.line_ending).encode("ascii")

    def _take_frame(self, buf: bytes) -> tuple[list[str] | None, int, str | None]:
        """(fields, consumed, error) of the first frame; noise before it is an error."""
        s = self.spec
        start, end = s.start.encode("ascii"), s.end.encode("ascii")
        i = 0
        while i < len(buf) and buf[i : i + 1] in (b" ", b"\r", b"\n", b"\t"):
            i += 1
        if i == len(buf):
            return None, i, None
        if not buf.startswith(start, i):
            nxt = buf.find(start, i)
            cut = len(buf) if nxt < 0 else nxt
            return None, cut, "bytes outside a frame"
        close = buf.find(end, i + len(start))
        if close < 0:
            if len(buf) - i > MAX_FRAME:
                return None, len(buf), "no end marker within 200 bytes"
            return None, i, None
        inner = buf[i + len(start) : close]
        consumed = close + len(end)
        if start in inner:
            return None, i + len(start) + inner.rfind(start), "start marker inside a frame"
        try:
            text = inner.decode("ascii")
        except UnicodeDecodeError:
            return None, consumed, "non-ASCII bytes"
        return text.split(s.separator), consumed, None

    def _index_out(self, index: int) -> str:
        return str(index + self.spec.index_base)

    def _index_in(self, token: str) -> int:
        value = decimal(token) - self.spec.index_base
        if value < 0:
            raise ValueError(f"LED number {token} below the index base {self.spec.index_base}")
        return value

    def _args(self, cmd: Command) -> list[str]:
        codes = self.spec.codes
        if isinstance(cmd, Hello):
            return [codes["hello"]]
        if isinstance(cmd, Light):
            level = [str(cmd.level)] if self.has_level else []
            return [codes["light"], self._index_out(cmd.index), *level]
        if isinstance(cmd, AllOff):
            return [codes["all_off"]]
        if isinstance(cmd, Shutter):
            return [codes["shutter"], str(cmd.pulse_ms)]
        if isinstance(cmd, Query):
            return [codes["query"]]
        raise TypeError(f"not a command: {cmd!r}")

    def _parse_args(self, fields: list[str]) -> Command:
        verb = self._verb_of_code.get(fields[0])
        args = fields[1:]
        if verb is None:
            raise _UnknownCode(f"unknown command code {fields[0]!r}")
        if verb == "light":
            if self.has_level:
                if len(args) != 2:
                    raise ValueError("light needs an LED and a level")
                return Light(self._index_in(args[0]), decimal(args[1]))
            if len(args) != 1:
                raise ValueError("light needs an LED")
            return Light(self._index_in(args[0]), self.spec.full_level)
        if verb == "shutter":
            if len(args) != 1:
                raise ValueError("shutter needs a pulse length")
            return Shutter(decimal(args[0]))
        if args:
            raise ValueError(f"{verb} takes no arguments")
        return {"hello": Hello(), "all_off": AllOff(), "query": Query()}[verb]

    # ------------------------------------------------------------ host side

    def encode_command(self, seq: int, cmd: Command) -> bytes:
        fields = self._args(cmd)
        if self.has_sequence:
            fields.insert(1, str(seq))
        return self._frame(fields)

    def decode_reply(self, buf: bytes, pending: Command | None) -> tuple[Reply | None, int]:
        fields, consumed, error = self._take_frame(buf)
        if error is not None:
            return Garbled(bytes(buf[:consumed]), error), consumed
        if fields is None:
            return None, consumed
        try:
            return self._parse_reply(fields), consumed
        except (ValueError, IndexError, KeyError) as exc:
            return Garbled(bytes(buf[:consumed]), f"unreadable reply ({exc})"), consumed

    def _parse_reply(self, fields: list[str]) -> Reply:
        """One frame's fields, read as the page writes them: each reply's fields exactly as
        many as it carries and its numbers decimal digits; anything else is garbled.

        Why: extra fields had been ignored and numbers read by ``int``, so on this link,
        which has no checksum, a damaged frame could read as another valid reply."""
        s = self.spec
        head, rest = fields[0], fields[1:]
        if head == s.ready_word:
            if not rest:
                return Banner(None)
            if len(rest) != 3:
                raise ValueError("a banner carries an id, a version and a count")
            return Banner(DomeIdentity(rest[0], rest[1], decimal(rest[2])))
        seq: int | None = None
        if head in (s.ok_word, s.err_word) and self.has_sequence:
            seq, rest = reply_seq(rest[0], SEQ_MAX, error=head == s.err_word), rest[1:]
        if head == s.err_word:
            return Nak(seq or None, decimal(rest[0]), s.separator.join(rest[1:]))
        if head != s.ok_word:
            raise ValueError(f"unknown reply word {head!r}")
        verb = self._verb_of_code.get(rest[0])
        if verb == "hello":
            if len(rest) != 4:
                raise ValueError("an identity carries a name, a version and a count")
            return Ack(seq, DomeIdentity(rest[1], rest[2], decimal(rest[3])))
        if verb == "query":
            if len(rest) != 3:
                raise ValueError("a lit state carries an index and a level")
            if rest[1] == "-1":
                return Ack(seq, LitState(None, decimal(rest[2])))
            return Ack(seq, LitState(self._index_in(rest[1]), decimal(rest[2])))
        return Ack(seq, self._parse_args(rest))


class _UnknownCode(ValueError):
    pass
