"""A dome's serial protocol described in the rig config: no Python for a simple firmware.

A description says, per verb (handshake, init, light, all off, shutter), which bytes to send
(a template) and what the firmware answers (nothing, any line, a regex, a fixed byte), plus the
link's timing (boot wait after opening, inter-command gap, framing by silence, blocking time).

Templates
  ``encoding = "text"``: the command is text; ``{index}`` (LED index + ``index_base``),
  ``{row}`` / ``{col}`` (index // columns, index % columns, from 0), ``{secs}`` (whole seconds
  of a timed LED), ``{mask}`` (hex digits of the bitmask of lit LEDs). Control characters come
  from TOML escapes (``"\\r"``, ``"\\u0000"``); text is sent as Latin-1.
  ``encoding = "bytes"``: whitespace-separated tokens, each two hex digits (``42``) or a
  placeholder: ``{index}``/``{row}``/``{col}`` one byte, ``{mask}`` ``ceil(led_count / 8)``
  bytes (``mask_bit_order``), ``{mapN}`` byte N of the LED's row in the LED map.
Reply patterns are regular expressions over the received text, with the same placeholders
substituted (escaped) before matching.
"""

from __future__ import annotations

import re
import string
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

TEXT_FIELDS = frozenset({"index", "row", "col", "secs", "mask"})
_MAP_TOKEN = re.compile(r"\{map(\d)\}")
_HEX_TOKEN = re.compile(r"[0-9A-Fa-f]{2}")


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class ReplySpec(_Strict):
    """What the firmware answers to one command."""

    kind: Literal["none", "line", "pattern", "byte"] = "none"
    pattern: str | None = Field(None, description="regex (kind = 'pattern')")
    byte: int | None = Field(None, ge=0, le=255, description="the ack byte (kind = 'byte')")
    timeout_s: float = Field(1.0, gt=0, le=120)

    @model_validator(mode="after")
    def _complete(self) -> ReplySpec:
        if self.kind == "pattern":
            if not self.pattern:
                raise ValueError("kind = 'pattern' needs a pattern (a regular expression)")
            check_pattern(self.pattern)
        elif self.pattern is not None:
            raise ValueError(f"pattern is only used with kind = 'pattern', not '{self.kind}'")
        if self.kind == "byte" and self.byte is None:
            raise ValueError("kind = 'byte' needs byte = the acknowledgement byte (0..255)")
        if self.kind != "byte" and self.byte is not None:
            raise ValueError(f"byte is only used with kind = 'byte', not '{self.kind}'")
        return self


class CommandSpec(_Strict):
    """One command: its template, its reply, and how long the firmware is busy after it."""

    send: str = Field(..., min_length=1)
    reply: ReplySpec = ReplySpec()
    #: The firmware blocks (or must not be spoken to) this long after the command.
    delay_after_s: float = Field(0.0, ge=0, le=120)


def check_pattern(pattern: str) -> None:
    """Refuse a reply pattern that does not compile or names an unknown placeholder."""
    for name in _placeholders(pattern):
        if name not in TEXT_FIELDS:
            raise ValueError(f"unknown placeholder {{{name}}} in pattern {pattern!r}")
    try:
        re.compile(render_pattern(pattern, {k: "0" for k in TEXT_FIELDS}))
    except re.error as exc:
        raise ValueError(f"pattern {pattern!r} is not a valid regular expression: {exc}") from None


def _placeholders(template: str) -> list[str]:
    try:
        return [f for _, f, _, _ in string.Formatter().parse(template) if f is not None]
    except ValueError as exc:
        raise ValueError(f"template {template!r}: {exc} (write {{{{ for a literal brace)") from None


def render_pattern(pattern: str, values: dict[str, str]) -> str:
    """The pattern with its placeholders replaced by escaped values."""
    return pattern.format(**{k: re.escape(v) for k, v in values.items()})


class ProtocolSpec(_Strict):
    """A whole dome protocol (a built-in profile is one of these, see ``dome_profiles``)."""

    name: str = Field("custom", min_length=1)
    led_count: int = Field(..., ge=1, le=1000)
    encoding: Literal["text", "bytes"] = "text"
    index_base: int = Field(0, ge=0, le=1)
    columns: int = Field(8, ge=1, le=1000, description="row = index // columns")
    mask_bit_order: Literal["lsb-first", "msb-first"] = "lsb-first"
    #: Bytes of ``{mask}`` (the firmware's, whatever led_count is wired); None: led_count / 8.
    mask_bytes: int | None = Field(None, ge=1, le=128)
    baudrate: int = Field(9600, gt=0, le=4_000_000)
    #: Seconds to wait after opening the port: boards that reset on open lose what is sent
    #: meanwhile. The text heard during the wait is kept (the probe shows it).
    boot_wait_s: float = Field(0.0, ge=0, le=30)
    #: Least gap between the end of one command and the next.
    min_gap_s: float = Field(0.0, ge=0, le=30)
    #: The firmware frames a command by this much silence (Arduino ``readString``).
    frame_silence_s: float = Field(0.0, ge=0, le=30)
    handshake: CommandSpec | None = None
    init: tuple[CommandSpec, ...] = ()
    light: CommandSpec
    #: None: the firmware has no all-off (a timed firmware switches LEDs off itself).
    all_off: CommandSpec | None = None
    shutter: CommandSpec | None = None
    #: Text (regex) whose appearance means the board rebooted (its boot banner).
    reset_pattern: str | None = None
    #: Text (regex) whose appearance means the firmware refused the command.
    error_pattern: str | None = None
    #: Text (regex) whose appearance means the firmware waits for a person, not a command
    #: (a menu, a calibration), and what to tell the user to do about it.
    waiting_pattern: str | None = None
    waiting_advice: str = ""
    #: Timed LEDs: the firmware lights for this long, blocks, then switches the LED off.
    light_on_s: float | None = Field(None, gt=0, le=600)
    #: Stepping firmware: ``light`` steps to the next LED and its reply names the LED lit
    #: (``{index}``); ``all_off`` switches off and rewinds to the first LED.
    stepping: bool = False
    #: The LED map (LED → bytes, ``{mapN}``): one row per LED, or None.
    led_map: tuple[tuple[int, ...], ...] | None = None
    #: Wait after opening until this text (regex) has arrived (the end of the boot banner),
    #: at most ``boot_wait_s``; without it the whole ``boot_wait_s`` is waited.
    ready_pattern: str | None = None
    #: The firmware lights every LED as it boots (the Nab sketch's ``setup()`` calls
    #: ``lightsOn()``) and its board resets when the port opens: an all-off that did not get
    #: through after an opening leaves the dome fully lit, which the lights line then says.
    boots_lit: bool = False
    #: A line for the docs and the probe (what the firmware is, where it comes from).
    note: str = ""

    @field_validator("reset_pattern", "error_pattern", "ready_pattern", "waiting_pattern")
    @classmethod
    def _regex(cls, value: str | None) -> str | None:
        if value is not None:
            try:
                re.compile(value)
            except re.error as exc:
                raise ValueError(f"{value!r} is not a valid regular expression: {exc}") from None
        return value

    @model_validator(mode="after")
    def _templates(self) -> ProtocolSpec:
        verbs: list[tuple[str, CommandSpec | None]] = [
            ("handshake", self.handshake),
            ("light", self.light),
            ("all_off", self.all_off),
            ("shutter", self.shutter),
        ] + [(f"init[{i}]", c) for i, c in enumerate(self.init)]
        for verb, cmd in verbs:
            if cmd is None:
                continue
            try:
                self._check_template(cmd.send)
            except ValueError as exc:
                raise ValueError(f"{verb}.send: {exc}") from None
        if self.light_on_s is not None and self.all_off is not None:
            raise ValueError(
                "light_on_s (a timed firmware) and all_off are exclusive: a timed firmware "
                "switches its LED off by itself"
            )
        if self.stepping:
            pat = self.light.reply.pattern or ""
            if self.light.reply.kind != "pattern" or "{index}" not in pat:
                raise ValueError(
                    "stepping = true needs light.reply.kind = 'pattern' with {index}: the "
                    "position is verified from the firmware's reply"
                )
            if self.all_off is None:
                raise ValueError("stepping = true needs all_off (it rewinds to the first LED)")
        if self.led_map is not None:
            if len(self.led_map) < self.led_count:
                # said with what to do: the bare count had left a user with 30 LEDs on an
                # Elexol board (24 outputs, one LED each by default) guessing
                rows = len(self.led_map)
                raise ValueError(
                    f"the LED map has {rows} rows for led_count = {self.led_count}: each LED "
                    f"needs its row (the outputs that light it), so give led_count = {rows} or "
                    "fewer, or an led_map_file (with led_map_section) that has a row per LED"
                )
            if any(not 0 <= b <= 255 for row in self.led_map for b in row):
                raise ValueError("LED map values must be bytes (0..255)")
        return self

    def _check_template(self, template: str) -> None:
        if self.encoding == "text":
            for name in _placeholders(template):
                if name not in TEXT_FIELDS:
                    raise ValueError(
                        f"unknown placeholder {{{name}}} in {template!r}; text templates know "
                        + ", ".join(f"{{{f}}}" for f in sorted(TEXT_FIELDS))
                    )
            try:
                template.format(**{k: "0" for k in TEXT_FIELDS}).encode("latin-1")
            except UnicodeEncodeError:
                raise ValueError(f"{template!r} has characters outside Latin-1") from None
            return
        for token in template.split():
            if _HEX_TOKEN.fullmatch(token) or token in ("{index}", "{row}", "{col}", "{mask}"):
                continue
            m = _MAP_TOKEN.fullmatch(token)
            if m:
                width = min((len(r) for r in self.led_map), default=0) if self.led_map else 0
                if int(m.group(1)) >= width:
                    raise ValueError(
                        f"{token} needs an LED map with at least {int(m.group(1)) + 1} bytes a row"
                    )
                continue
            raise ValueError(
                f"token {token!r}: a bytes template is two-digit hex bytes and {{index}}, "
                "{row}, {col}, {mask}, {mapN}, separated by spaces"
            )

    # ------------------------------------------------------------------ rendering

    @property
    def window_s(self) -> int | None:
        """A timed firmware's on-window: ``light_on_s`` sent as whole seconds (at least 1), the
        ``{secs}`` of the light command; None for a firmware whose LEDs stay on until told."""
        return None if self.light_on_s is None else max(1, round(self.light_on_s))

    def values(self, index: int | None, lit: frozenset[int]) -> dict[str, int]:
        i = -1 if index is None else index
        secs = self.window_s or 0
        return {
            "index": i + self.index_base,
            "row": i // self.columns,
            "col": i % self.columns,
            "secs": secs,
        }

    def mask_of(self, lit: frozenset[int]) -> bytes:
        out = bytearray(self.mask_bytes or (self.led_count + 7) // 8)
        for i in lit:
            bit = i % 8 if self.mask_bit_order == "lsb-first" else 7 - i % 8
            out[i // 8] |= 1 << bit
        return bytes(out)

    def render(self, template: str, index: int | None, lit: frozenset[int]) -> bytes:
        """The bytes of ``template`` for LED ``index`` with ``lit`` the LEDs to be on."""
        v = self.values(index, lit)
        mask = self.mask_of(lit)
        if self.encoding == "text":
            return template.format(**v, mask=mask.hex().upper()).encode("latin-1")
        out = bytearray()
        for token in template.split():
            if _HEX_TOKEN.fullmatch(token):
                out.append(int(token, 16))
            elif token == "{mask}":
                out += mask
            elif (m := _MAP_TOKEN.fullmatch(token)) is not None:
                row = self.led_map[index] if self.led_map and index is not None else ()
                out.append(row[int(m.group(1))] if row else 0)
            else:
                out.append(v[token.strip("{}")] & 0xFF)
        return bytes(out)

    def step_regex(self, pattern: str) -> re.Pattern[str]:
        """``pattern`` with ``{index}`` capturing any number (which LED a step really lit)."""
        v = {k: re.escape(str(x)) for k, x in self.values(0, frozenset()).items()}
        v.update(mask="", index=r"(\d+)")
        return re.compile(pattern.format(**v))

    def reply_regex(self, pattern: str, index: int | None) -> re.Pattern[str]:
        v = {k: str(x) for k, x in self.values(index, frozenset()).items()}
        v["mask"] = ""
        return re.compile(render_pattern(pattern, v))


class MissingSection(ValueError):
    """The map file is fine but has no section of the name asked for: the fault is in the rig
    config's ``led_map_section``, not in the file (a typo there had been named as the file's)."""


def parse_led_map(text: str, section: str | None, source: str) -> tuple[tuple[int, ...], ...]:
    """LED rows from an rtiacquire-style map file: ``** name **`` sections of hex triples.

    The rows of ``section`` (the first section when None), in order; a bad line is refused
    naming the file and line.
    """
    maps: dict[str, list[tuple[int, ...]]] = {}
    current: str | None = None
    for n, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        head = re.fullmatch(r"\*\*\s*(.+?)\s*\*\*", s)
        if head:
            current = head.group(1)
            if current in maps:
                raise ValueError(f"{source}:{n}: section '{current}' is repeated")
            maps[current] = []
            continue
        parts = [p for p in re.split(r"[\s,]+", s) if p]
        try:
            row = tuple(int(p, 16) for p in parts)
        except ValueError:
            raise ValueError(f"{source}:{n}: expected hex bytes like '0x01, 0x00, 0x00'") from None
        if current is None:
            raise ValueError(f"{source}:{n}: bytes before the first '** name **' line")
        if not row or any(not 0 <= b <= 255 for b in row):
            raise ValueError(f"{source}:{n}: values must be bytes 00..ff")
        maps[current].append(row)
    if not maps:
        raise ValueError(f"{source}: no '** name **' section")
    name = section or next(iter(maps))
    if name not in maps:
        raise MissingSection(f"{source} has no section '{name}' (sections: {', '.join(maps)})")
    return tuple(maps[name])
