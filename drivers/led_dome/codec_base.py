"""What every dome protocol profile's codec offers, on both sides of the wire.

A codec is pure: it turns messages into bytes and parses bytes from the front of a buffer,
returning how many bytes it consumed, so that transports and the emulator own all I/O. Each
profile implements both sides (host and firmware) so that the emulator speaks exactly the bytes
the driver expects, and a byte-exact test covers both directions.
"""

from __future__ import annotations

from typing import Protocol

from rti_rig.drivers.led_dome.messages import BadRequest, Command, DomeIdentity, Reply


class DomeCodec(Protocol):
    """Bytes of one protocol profile."""

    #: Profile name as written in the rig config.
    profile: str
    #: True when replies carry the command's sequence number (stale replies can be recognised).
    has_sequence: bool
    #: True when the light command can carry the firmware watchdog time.
    has_watchdog: bool
    #: True when the light command carries an intensity level (else only full intensity).
    has_level: bool

    def next_seq(self, seq: int) -> int:
        """The sequence number after ``seq`` (wraps within the profile's range)."""
        ...

    # host side
    def encode_command(self, seq: int, cmd: Command) -> bytes: ...

    def decode_reply(self, buf: bytes, pending: Command | None) -> tuple[Reply | None, int]:
        """Parse one reply from the front of ``buf``: (reply, bytes consumed).

        ``(None, n)`` means more bytes are needed after dropping ``n`` bytes of filler
        (whitespace between frames; usually ``n == 0``). ``pending`` is the command awaiting
        an answer (binary replies have a length that depends on it).
        """
        ...

    # firmware side
    def decode_command(
        self, buf: bytes
    ) -> tuple[tuple[int | None, Command] | BadRequest | None, int]:
        """Parse one command from the front of ``buf``: ((seq, command) | BadRequest, consumed)."""
        ...

    def encode_reply(self, reply: Reply, cmd: Command | None) -> bytes:
        """Bytes of an Ack, Nak or Banner; ``cmd`` is the command being answered."""
        ...

    def encode_banner(self, identity: DomeIdentity) -> bytes: ...


def xor_checksum(data: bytes) -> int:
    """XOR of all bytes (the NMEA-style check used by the default and binary profiles)."""
    value = 0
    for b in data:
        value ^= b
    return value
