"""The verbs a host says to a dome and the answers a dome gives, independent of bytes.

Every profile's codec turns the commands into bytes and the board's bytes into replies (the
host's side only: the emulated board reads the wire from the protocol page on its own), so a
byte-exact test of a profile is a table of (message, bytes) pairs.
"""

from __future__ import annotations

from dataclasses import dataclass

# ---------------------------------------------------------------- host -> dome commands


@dataclass(frozen=True)
class Hello:
    """Ask for firmware id, version and LED count."""


@dataclass(frozen=True)
class Light:
    """Light LED ``index`` (0-based) alone at PWM ``level``; every other LED goes off.

    ``max_on_ms`` asks the firmware to switch the LED off by itself after that time (a watchdog
    that still protects the LED if the host dies); ``None`` when the profile cannot carry it.
    """

    index: int
    level: int
    max_on_ms: int | None = None


@dataclass(frozen=True)
class AllOff:
    """Every LED off: the dome's safe state."""


@dataclass(frozen=True)
class Shutter:
    """Pulse the camera remote-release line for ``pulse_ms`` milliseconds."""

    pulse_ms: int


@dataclass(frozen=True)
class Query:
    """Ask which LED the firmware really has lit (after watchdogs, faults and resets)."""


Command = Hello | Light | AllOff | Shutter | Query


def describe(cmd: Command) -> str:
    """Short human name of a command, used in error messages and logs."""
    if isinstance(cmd, Light):
        return f"light LED {cmd.index} at level {cmd.level}"
    if isinstance(cmd, Shutter):
        return f"shutter pulse {cmd.pulse_ms} ms"
    if isinstance(cmd, Hello):
        return "handshake"
    if isinstance(cmd, AllOff):
        return "all off"
    return "query lit LED"


# ---------------------------------------------------------------- dome -> host replies


@dataclass(frozen=True)
class DomeIdentity:
    """What the handshake and the boot banner tell about the board."""

    firmware_id: str
    version: str
    led_count: int


@dataclass(frozen=True)
class LitState:
    """The firmware's own view: ``index`` is ``None`` when everything is off."""

    index: int | None
    level: int


@dataclass(frozen=True)
class Ack:
    """Command ``seq`` done. ``echo`` repeats what was executed so that the host can check it.

    ``echo`` is the command as the firmware understood it (``Light`` with the index and level
    it really used), a :class:`DomeIdentity` for a handshake, a :class:`LitState` for a query,
    or ``None`` when the profile's acknowledgement carries nothing but the sequence number.
    ``seq`` is ``None`` for profiles without sequence numbers.
    """

    seq: int | None
    echo: Command | DomeIdentity | LitState | None = None


@dataclass(frozen=True)
class Nak:
    """Command ``seq`` refused with error ``code`` (see :data:`ERROR_CODES`)."""

    seq: int | None
    code: int
    text: str = ""


@dataclass(frozen=True)
class Banner:
    """The board (re)booted: after opening the port, or a reset in the middle of a session."""

    identity: DomeIdentity | None


@dataclass(frozen=True)
class Garbled:
    """Bytes that are not a valid reply (bad checksum, bad syntax, unknown byte)."""

    raw: bytes
    reason: str


Reply = Ack | Nak | Banner | Garbled


# Error codes shared by every profile (binary carries them in 6 bits).
ERR_UNKNOWN_COMMAND = 1
ERR_BAD_ARGUMENT = 2
ERR_LED_OUT_OF_RANGE = 3
ERR_LED_FAULT = 4
ERR_THERMAL = 5
ERR_BAD_CHECKSUM = 6

ERROR_CODES: dict[int, str] = {
    ERR_UNKNOWN_COMMAND: "unknown command",
    ERR_BAD_ARGUMENT: "bad argument",
    ERR_LED_OUT_OF_RANGE: "LED index out of range",
    ERR_LED_FAULT: "LED fault (open circuit: the LED draws no current)",
    ERR_THERMAL: "thermal cut-out in the firmware",
    ERR_BAD_CHECKSUM: "bad checksum: the command arrived garbled",
}

#: Error codes that mean the command did not arrive as sent, so resending it may help. The host
#: validates verbs, LED indices and levels before sending, so when the firmware still finds one
#: unknown or out of range, the bytes were damaged on the way (profiles without a checksum only
#: notice it this way). A dead LED or a thermal cut-out is definitive.
TRANSIENT_ERROR_CODES = frozenset(
    {ERR_BAD_CHECKSUM, ERR_UNKNOWN_COMMAND, ERR_BAD_ARGUMENT, ERR_LED_OUT_OF_RANGE}
)


def error_text(code: int) -> str:
    return ERROR_CODES.get(code, f"firmware error {code}")
