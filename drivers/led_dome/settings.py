"""The ``[dome]`` serial settings of a rig config, validated before any port is opened.

Every field a user can get wrong is checked here with a message that says what is allowed, so
that the rig config loader can report ``rig.toml: key 'dome.framed.codes.light': ...`` before
the session starts.
"""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from rti_rig.core.validation_text import error_text, key_of, table_keys
from rti_rig.drivers.led_dome.dome_profiles import (
    all_profiles,
    bootloader_touch_baud,
    builtin_spec,
    described_profiles,
    merge,
    no_dimming,
)
from rti_rig.drivers.led_dome.protocol_spec import ProtocolSpec


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class DefaultProfileOptions(_Strict):
    """Options of the ``default`` line protocol (``docs/protocols/led-dome.md``)."""

    checksum: bool = Field(True, description="append and check the '*HH' XOR checksum")


class FramedCodes(_Strict):
    """The command code sent as the first field of each frame."""

    hello: str = "9"
    light: str = "3"
    all_off: str = "0"
    shutter: str = "6"
    query: str = "8"

    @model_validator(mode="after")
    def _distinct(self) -> FramedCodes:
        codes = [self.hello, self.light, self.all_off, self.shutter, self.query]
        if len(set(codes)) != len(codes):
            raise ValueError(f"command codes must differ from each other, got {codes}")
        for code in codes:
            if not code or not code.isascii() or not code.isprintable():
                raise ValueError(f"command code {code!r} must be printable ASCII, not empty")
        return self


class FramedOptions(_Strict):
    """Options of the ``framed`` ``<cmd,arg>`` profile (markers, codes, numbering, words)."""

    start: str = "<"
    end: str = ">"
    separator: str = ","
    line_ending: Literal["", "\n", "\r\n"] = ""
    codes: FramedCodes = FramedCodes()
    index_base: Literal[0, 1] = 0
    send_level: bool = True
    sequence: bool = True
    ok_word: str = "OK"
    err_word: str = "ERR"
    ready_word: str = "READY"

    @model_validator(mode="after")
    def _markers(self) -> FramedOptions:
        marks = {"start": self.start, "end": self.end, "separator": self.separator}
        for key, value in marks.items():
            if len(value) != 1 or not value.isascii() or value.isalnum() or value.isspace():
                raise ValueError(
                    f"{key} must be one printable ASCII punctuation character, got {value!r}"
                )
        if len(set(marks.values())) != 3:
            raise ValueError(f"start, end and separator must differ, got {marks}")
        for verb, code in self.codes.model_dump().items():
            clash = [k for k, v in marks.items() if v in code]
            if clash:
                raise ValueError(
                    f"command code {verb} = {code!r} contains the {clash[0]} character; "
                    "it would break the frame"
                )
        words = [self.ok_word, self.err_word, self.ready_word]
        if len(set(words)) != 3 or not all(w.isascii() and w.isalnum() for w in words):
            raise ValueError(f"ok_word, err_word, ready_word must be distinct ASCII words: {words}")
        return self


class BinaryOptions(_Strict):
    """Options of the ``binary`` profile (7-byte commands, one-byte sequence ack)."""

    start_byte: int = Field(0xA5, ge=0, le=0xFE, description="first byte of each command")
    index_base: Literal[0, 1] = 0


class ThermalSettings(_Strict):
    """Per-LED protection: longest continuous on-time, highest duty over a sliding window."""

    max_on_s: float = Field(10.0, gt=0, le=3600)
    max_duty: float = Field(0.5, gt=0, le=1)
    duty_window_s: float = Field(60.0, gt=0, le=86400)

    @model_validator(mode="after")
    def _consistent(self) -> ThermalSettings:
        if self.max_on_s > self.max_duty * self.duty_window_s:
            raise ValueError(
                f"max_on_s ({self.max_on_s} s) is longer than max_duty × duty_window_s "
                f"({self.max_duty * self.duty_window_s:g} s): a single lighting would break the "
                "duty limit; lower max_on_s or widen the window"
            )
        return self


CodecProfile = Literal["default", "framed", "binary"]


def _same_number(a: Any, b: Any) -> bool:
    """Whether two config values are the same number (``9600`` and ``9600.0``; a quoted one
    is compared by its text and refused as quoted elsewhere)."""
    if isinstance(a, bool) or isinstance(b, bool):
        return False
    try:
        return float(a) == float(b)
    except (TypeError, ValueError):
        return False


class ProtocolKeyError(ValueError):
    """A refused key of ``[dome.serial.protocol]``: its place in that table and what is wrong.

    Why a type of its own: the description is checked inside ``[dome.serial]``'s validation, so
    pydantic would name only ``dome.serial``; the config loader reads ``loc`` to name the full
    key (``dome.serial.protocol.bogus_key``), worded as every other table words it."""

    def __init__(self, loc: tuple[Any, ...], text: str) -> None:
        self.loc = loc
        self.text = text
        where = key_of(("protocol", *loc))
        super().__init__(f"{where}: {text}")


class DomeSerialSettings(_Strict):
    """How to reach an LED dome over a serial port, and the policy that keeps it safe."""

    port: str = Field(..., min_length=1, description="e.g. /dev/ttyACM0, COM3, loop://")
    baudrate: int = Field(115200, gt=0, le=4_000_000)
    #: default / framed / binary (this project's own protocols), a built-in firmware's name
    #: (``dome_profiles``), or "custom" with a full [dome.serial.protocol] description.
    profile: str = "default"
    #: The protocol description (profile = "custom"), or fields laid over a built-in one.
    protocol: dict[str, Any] | None = None
    #: An LED map file (rtiacquire ``led-maps.txt`` format) and the section to use.
    led_map_file: str | None = None
    led_map_section: str | None = None
    default: DefaultProfileOptions | None = None
    framed: FramedOptions | None = None
    binary: BinaryOptions | None = None
    reply_timeout_s: float = Field(0.5, gt=0, le=30)
    ready_timeout_s: float = Field(3.0, ge=0, le=60)
    retries: int = Field(2, ge=0, le=10)
    retry_backoff_s: float = Field(0.05, ge=0, le=10)
    reconnect_attempts: int = Field(3, ge=0, le=20)
    reconnect_backoff_s: float = Field(1.0, ge=0, le=60)
    max_level: int = Field(255, ge=1, le=65535)
    shutter_pulse_ms: int = Field(50, ge=1, le=10_000)
    confirm_with_query: bool = Field(
        False, description="after lighting, ask the firmware which LED is lit (binary: no echo)"
    )
    expected_led_count: int | None = Field(None, ge=1, le=1000)
    #: Whether the board's firmware measures LED current and answers error 4 (LED fault) for a
    #: dead LED, as this project's protocols define. The protocol cannot tell: a board built
    #: without current sensing acknowledges a dead LED like a good one. ``false`` makes
    #: ``rti-rig check`` say what it established ("acknowledged by the board; lit not verified")
    #: instead of "passed". This project's own profiles only (a described firmware senses none).
    senses_led_current: bool = Field(
        True,
        description="the firmware answers error 4 for a dead LED (false: it measures no current)",
    )
    thermal: ThermalSettings = ThermalSettings()
    intensity_correction: list[float] | None = Field(
        None, description="per-LED factor (0, 1] applied to the requested intensity"
    )

    @field_validator("intensity_correction")
    @classmethod
    def _factors(cls, value: list[float] | None) -> list[float] | None:
        if value is None:
            return value
        if not value:
            raise ValueError("intensity_correction is empty; omit it or give one factor per LED")
        for i, f in enumerate(value):
            if not math.isfinite(f) or not 0 < f <= 1:
                raise ValueError(
                    f"factor for LED {i} is {f}; factors must be in (0, 1] (divide the list by "
                    "its largest value)"
                )
        return value

    @field_validator("profile")
    @classmethod
    def _known_profile(cls, value: str) -> str:
        if value not in all_profiles():
            raise ValueError(
                f"profile '{value}' is not known: this project's own protocols are 'default', "
                "'framed' or 'binary'; real firmwares: "
                + ", ".join(described_profiles())
                + "; or 'custom' with a [dome.serial.protocol] description (docs/domes.md)"
            )
        return value

    @model_validator(mode="before")
    @classmethod
    def _profile_baud(cls, data: Any) -> Any:
        """A built-in firmware's baud rate unless the config gives one.

        The port opens at ``[dome.serial] baudrate`` when it is given; a different
        ``[dome.serial.protocol] baudrate`` beside it was silently ignored, so a user who set
        the firmware's rate in the protocol table got a dome that never answered (or the rate
        they did not mean). Both given and different is refused, naming both keys.
        """
        if not isinstance(data, dict):
            return data
        over = data.get("protocol") if isinstance(data.get("protocol"), dict) else {}
        if "baudrate" in data and "baudrate" in over:
            ours, theirs = data["baudrate"], over["baudrate"]
            if not _same_number(ours, theirs):
                raise ValueError(
                    f"dome.serial.baudrate = {ours!r} and dome.serial.protocol.baudrate = "
                    f"{theirs!r} disagree, and the port opens at one rate only: give the "
                    "firmware's baud rate once (remove one of the two keys) or make them equal"
                )
        if "baudrate" not in data:
            name = data.get("profile")
            if isinstance(name, str) and name in described_profiles():
                data = {**data, "baudrate": over.get("baudrate", builtin_spec(name)["baudrate"])}
            elif name == "custom":
                data = {**data, "baudrate": over.get("baudrate", 9600)}
        return data

    @model_validator(mode="after")
    def _profile_options(self) -> DomeSerialSettings:
        described = self.profile in described_profiles() or self.profile == "custom"
        if not described and (self.protocol is not None or self.led_map_file is not None):
            raise ValueError(
                f"[dome.serial.protocol] and led_map_file describe a firmware's protocol; the "
                f"'{self.profile}' profile is this project's own: remove them or choose a "
                "firmware profile (or 'custom')"
            )
        if described and "senses_led_current" in self.model_fields_set:
            raise ValueError(
                f"senses_led_current is for this project's own protocols; the '{self.profile}' "
                "firmware answers no LED fault (its check says each LED 'acknowledged by the "
                "board'): remove the key"
            )
        if self.profile == "custom" and self.protocol is None:
            raise ValueError(
                "profile = 'custom' needs a [dome.serial.protocol] table describing the firmware "
                "(docs/domes.md, 'Describing a new dome')"
            )
        touch = bootloader_touch_baud(self.profile)
        if touch is not None and self.baudrate == touch:
            # refused here, at load: a check or run would open the port at this rate, and its
            # close (DTR dropping at 1200 baud) jumps an ATmega32u4 into its bootloader, the
            # dome then gone from the port for its next command or a resumed run
            key = "dome.serial.baudrate"
            if self.protocol is not None and "baudrate" in self.protocol:
                key = "dome.serial.protocol.baudrate"
            raise ValueError(
                f"{key} = {touch} is the rate at which the {self.profile} firmware's board (an "
                f"ATmega32u4 on its own USB) jumps to its bootloader when the port closes (the "
                f"Arduino 1200-baud touch), so no port is opened at it; this board takes any "
                f"other rate: remove {key} (the firmware's own "
                f"{builtin_spec(self.profile)['baudrate']} is used) or set another rate"
            )
        if described:
            self.protocol_spec()  # refuse a bad description now, naming its key
        for other in ("default", "framed", "binary"):
            if other != self.profile and getattr(self, other) is not None:
                # the table is a sub-table of [dome.serial]: "[dome.framed]" had been named,
                # a table no config has (and one the loader refuses as an unknown key)
                raise ValueError(
                    f"options for the '{other}' profile are given but profile = "
                    f"'{self.profile}'; remove [dome.serial.{other}] or set profile = '{other}'"
                )
        if self.profile == "binary" and self.max_level > 255:
            raise ValueError("the binary profile carries the level in one byte: max_level ≤ 255")
        n = self.expected_led_count
        corr = self.intensity_correction
        if n is not None and corr is not None and len(corr) != n:
            raise ValueError(
                f"intensity_correction has {len(self.intensity_correction)} factors for "
                f"expected_led_count = {n}"
            )
        return self

    def protocol_spec(self, led_map: tuple[tuple[int, ...], ...] | None = None) -> ProtocolSpec:
        """The validated protocol description of a firmware profile (built-in or custom).

        ``led_map``: rows read from ``led_map_file`` (they set the LED count too).
        """
        base: dict[str, Any] = (
            builtin_spec(self.profile) if self.profile in described_profiles() else {}
        )
        merged = merge(base, self.protocol or {})
        merged["baudrate"] = self.baudrate
        if led_map is not None:
            merged["led_map"] = [list(r) for r in led_map]
            merged["led_count"] = len(led_map)
        try:
            return ProtocolSpec.model_validate(merged)
        except ValidationError as exc:
            first = exc.errors()[0]
            known = table_keys(ProtocolSpec, tuple(first["loc"]))
            raise ProtocolKeyError(
                tuple(first["loc"]), error_text(first, known, ProtocolSpec)
            ) from None

    def led_count_source(self) -> str:
        """Where a firmware profile's LED count comes from, as a check or error should say it.

        None of the described firmwares reports how many LEDs it has, so the count is never
        the board's word: it is the rig config's ``led_count``, its LED map's rows, or the
        built-in profile's own default. Saying which keeps a check from reading as if the
        board had counted its LEDs."""
        if self.led_map_file is not None:
            return "the rows of the LED map file (dome.serial.led_map_file)"
        if self.protocol is not None and "led_count" in self.protocol:
            return "the rig config (dome.serial.protocol.led_count)"
        return f"the {self.profile} profile's own count (no led_count in [dome.serial.protocol])"

    def dimming_refusal(self) -> str | None:
        """Why this link cannot dim an LED, naming the firmware or profile, or None where it can.

        The one answer to "can this dome be dimmed LED by LED" (``calibrate-lights``, an
        ``intensity_correction`` at config load, the metering's "evened out", the QA verdict of
        a recorded session): see :func:`dimming_refusal_of`."""
        return dimming_refusal_of(self.profile, (self.framed or FramedOptions()).send_level)

    @property
    def can_dim(self) -> bool:
        """The link's light command carries a brightness (see :meth:`dimming_refusal`)."""
        return self.dimming_refusal() is None

    @property
    def is_described(self) -> bool:
        """True for firmware profiles (driven from a protocol description, not a codec)."""
        return self.profile in described_profiles() or self.profile == "custom"

    def check_led_count(self, count: int) -> str | None:
        """Why ``count`` LEDs (e.g. from the dome's ``.lp``) do not fit these settings, or None."""
        if self.expected_led_count is not None and self.expected_led_count != count:
            return f"expected_led_count = {self.expected_led_count} but {count} LEDs given"
        corr = self.intensity_correction
        if corr is not None and len(corr) != count:
            return f"intensity_correction has {len(corr)} factors for {count} LEDs"
        return None


#: What a light correction needs, said wherever one is refused for a link that cannot dim: the
#: links :func:`dimming_refusal_of` lets through, worded once beside it (the config loader and
#: ``calibrate-lights`` had each spelled the list, free to drift from this function).
DIMMING_LINK = (
    "a link whose light command carries a brightness (the 'default' or 'binary' profile, or "
    "'framed' with send_level = true)"
)

#: Where a dome that cannot dim is evened out instead: its images, divided by the light gains.
IMAGE_GAINS_REMEDY = "rti_rig.reconstruct.apply_light_gains"


def dimming_refusal_of(profile: str, send_level: bool = True) -> str | None:
    """Why a link of ``profile`` (``framed``: with ``send_level``) cannot dim an LED, naming the
    firmware or profile, or None where it can.

    A function of the two keys it depends on, so a session's recorded ``[dome.serial]`` table
    is judged as its loaded settings are (the QA verdict had advised ``calibrate-lights`` for
    every recorded serial dome, a command that refuses an on/off firmware). This project's
    ``default`` and ``binary`` protocols carry a PWM level in every light command, ``framed``
    does unless ``send_level = false``, and no real firmware described here carries one
    (:func:`~rti_rig.drivers.led_dome.dome_profiles.no_dimming`). Raises ``KeyError`` for a
    name that is no profile of this version (the loaded settings never hold one)."""
    if profile in ("default", "binary"):
        return None
    if profile == "framed":
        if send_level:
            return None
        return (
            "the 'framed' profile with send_level = false cannot dim an LED: its light "
            "frames carry no level, only full intensity"
        )
    if profile == "custom":
        return (
            "a 'custom' firmware described in [dome.serial.protocol] cannot be dimmed: a "
            "description has no brightness placeholder, its light command switches an LED on"
        )
    return f"the {profile} firmware cannot dim an LED: {no_dimming(profile)}"
