"""What every dome protocol profile's codec offers: the host's side of the wire.

A codec is pure: it turns commands into bytes and parses replies from the front of a buffer,
returning how many bytes it consumed, so that the transport owns all I/O. It is the host's side
only: the emulated board reads and writes the wire from docs/protocols/led-dome.md on its own
(``rti_rig.simulator.own_protocols``), and the codecs' tests hold the page's bytes. Why: the
codecs had a firmware side too, used by their own test alone, which accepted what the page
refuses (sequence 0; 128 on the binary link, whose ack byte reads as an error).
"""

from __future__ import annotations

from typing import Protocol

from rti_rig.drivers.led_dome.messages import Command, Reply


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


def xor_checksum(data: bytes) -> int:
    """XOR of all bytes (the NMEA-style check used by the default and binary profiles)."""
    value = 0
    for b in data:
        value ^= b
    return value


def decimal(token: str, *, signed: bool = False) -> int:
    """A number field of a text profile's reply as the page writes it: decimal ASCII digits, a
    ``-`` first only where ``signed`` (the default profile's query ``-1``).

    Why: ``int`` also reads ``+7``, `` 7`` and ``1_0``, so a reply damaged on a link without
    a checksum (``framed``, or ``default`` with ``checksum = false``) could still read as
    numbers, and other numbers than were sent (``<OK,1,9,RTIDOME,1.2.0, 8>``, the count
    ``48`` damaged, as a board of 8 LEDs)."""
    digits = token[1:] if signed and token.startswith("-") else token
    if not (digits.isascii() and digits.isdigit()):
        raise ValueError(f"{token!r} is no decimal number")
    return int(token)


def reply_seq(token: str, seq_max: int, *, error: bool = False) -> int:
    """A text profile's reply sequence number: 1..``seq_max``, or 0 in an error too damaged to
    read it by."""
    seq = decimal(token)
    if not (0 if error else 1) <= seq <= seq_max:
        raise ValueError(f"sequence number {seq} outside 1..{seq_max}")
    return seq
