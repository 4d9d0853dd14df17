"""The time a half-duplex Dynamixel bus takes, charged to an emulated arm's clock.

A real host waits, for each exchange, for its instruction's bytes to cross the wire, the
servo's Return Delay Time, then the status bytes (ROBOTIS e-manual: X series, Physical
Connection "8bit, 1stop, No Parity", so 10 bits a byte; Return Delay Time (9) in 2 µs units,
250 = 500 µs from the factory). The emulated ports (the in-process
:class:`~rti_rig.simulator.dynamixel_emulator.InProcessPort`, the pty link's
:class:`~rti_rig.simulator.dynamixel_pty.EmulatedLinkPortHandler`) hand the emulator's status
over at once, so a dry run on a :class:`~rti_rig.core.clock.VirtualClock`
had paid none of it: the session time it reported was about 2.5 % short of the same schedule
on a bus at 57600 baud. :class:`BusTime` charges it, on the host's side of the port, as the
host meets it: an instruction's bytes as it writes them (before the servos act on it), each
status's Return Delay Time and bytes as it reads them. A status the host never reads (dropped
by ``clearPort``) is not charged: the host did not wait for it. A status that never comes (a
silent servo, a chain without power, a status lost on the wire) costs the host its whole
reply window (the SDK's ``setPacketTimeout``: the status's bytes at the baud rate plus
``LATENCY_TIMER * 2 + 2`` ms, 34 ms and more at 57600), and a late one its lateness or the
window, the shorter (:meth:`BusTime.window_opened`, :meth:`BusTime.waited`): they had cost the
clock nothing, so a dry run with faults reported a session shorter than the real bus.

Not modelled: the USB-serial adapter's latency (an FTDI's latency timer holds a short status up
to 16 ms by default, 1 ms once set low), which a host on real hardware adds to each read.
"""

from __future__ import annotations

from typing import Any

from rti_rig.core.clock import Clock
from rti_rig.simulator import dynamixel_table as tbl
from rti_rig.simulator import dynamixel_wire as wire

#: Bits one byte takes on the wire: start bit, 8 data bits, stop bit (ROBOTIS e-manual, X
#: series specifications, Physical Connection: "8bit, 1stop, No Parity").
BITS_PER_BYTE = 10
#: Return Delay Time (9) unit, seconds (e-manual, X-series control table: 2 [μsec]).
RETURN_DELAY_UNIT_S = 2e-6


def wire_time_s(n_bytes: int, baud: int | None) -> float:
    """Seconds ``n_bytes`` take on the wire at ``baud`` (none when the rate is unknown)."""
    return n_bytes * BITS_PER_BYTE / baud if baud else 0.0


def return_delay_s(servos: dict[int, Any], dxl_id: int) -> float:
    """Servo ``dxl_id``'s Return Delay Time (9) as its table holds it now, seconds (0 for an
    id not on the bus)."""
    servo = servos.get(dxl_id)
    return servo.get(tbl.RETURN_DELAY_TIME) * RETURN_DELAY_UNIT_S if servo is not None else 0.0


class BusTime:
    """Charges ``clock`` with the bus's time, for a port at the baud rate ``baud()`` gives.

    ``servos``: the emulator's servos by id, whose Return Delay Time each status waits."""

    def __init__(self, clock: Clock, servos: dict[int, Any], baud: Any) -> None:
        self.clock = clock
        self._servos = servos
        self._baud = baud
        #: what was read of a packet's first 7 bytes (header, ID, Length), not yet whole
        self._head = bytearray()
        #: bytes still to come of the packet being read, by its Length
        self._left = 0
        #: the clock's time when the host's reply window opened (None: no window open)
        self._window_from: float | None = None

    def sent(self, data: bytes) -> None:
        """The host wrote ``data``: its bytes cross the wire before any servo acts on them."""
        self.clock.sleep(wire_time_s(len(data), self._baud()))

    def heard(self, data: bytes) -> None:
        """The host read ``data``: its bytes' wire time, and the Return Delay Time of each
        status packet that starts in it (a Sync Read's servos answer one after another, each
        after its own delay, as the e-manual's Sync Read describes)."""
        if not data:
            return
        self.clock.sleep(self._delays_begun(data) + wire_time_s(len(data), self._baud()))

    def _delays_begun(self, data: bytes) -> float:
        """The Return Delay Time of each status packet that begins in ``data``, the packets
        taken by their Length as the emulator's codec takes them
        (:class:`~rti_rig.simulator.dynamixel_wire.InstructionReader`).

        Why by Length: a packet's CRC is not stuffed, so ``FF FF FD 00`` can end one (a
        status whose parameters end ``FF FF``, a negative Present Velocity, with CRC
        0x00FD); found by the header alone, it had been read as a packet that took the next
        status's header as its ID, and that servo's delay went uncharged."""
        delay = 0.0
        buf = self._head + data
        while buf:
            if self._left:
                n = min(self._left, len(buf))
                del buf[:n]
                self._left -= n
                continue
            start = buf.find(wire.HEADER)
            if start < 0:
                del buf[: max(0, len(buf) - (len(wire.HEADER) - 1))]  # a header cut in two
                break
            del buf[:start]
            if len(buf) < 7:
                break
            dxl_id, length = buf[4], buf[5] | buf[6] << 8
            if not wire.begins_packet(dxl_id, length):
                del buf[: len(wire.HEADER)]  # not a packet, as the codec skips it
                continue
            delay += return_delay_s(self._servos, dxl_id)
            self._left = length
            del buf[:7]
        self._head = buf
        return delay

    def window_opened(self) -> None:
        """The host opened its reply window (the SDK's ``setPacketTimeout``): what it then
        waits is counted from now, as the SDK counts it."""
        self._window_from = self.clock.now()

    def waited(self, ms: float, gave_up: bool) -> None:
        """The host waited until ``ms`` after its window opened: the whole window when it
        ``gave_up`` on a status that never came (or came after it), a late status's lateness
        when it came within. Only what the clock has not yet run since the window opened
        (the bytes read meanwhile) is charged; a window given up is closed, so a host asking
        again after its end pays nothing more."""
        if self._window_from is None:
            return
        left = self._window_from + ms / 1000.0 - self.clock.now()
        if left > 0:
            self.clock.sleep(left)
        if gave_up:
            self._window_from = None

    def cleared(self) -> None:
        """The host discarded what had arrived: a packet cut short there starts no other."""
        self._head.clear()
        self._left = 0
