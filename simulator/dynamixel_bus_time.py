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
by ``clearPort``) is not charged: the host did not wait for it.

Not modelled: the USB-serial adapter's latency (an FTDI's latency timer holds a short status up
to 16 ms by default, 1 ms once set low), which a host on real hardware adds to each read.
"""

from __future__ import annotations

from typing import Any

from rti_rig.core.clock import Clock
from rti_rig.simulator import dynamixel_table as tbl

#: Bits one byte takes on the wire: start bit, 8 data bits, stop bit (ROBOTIS e-manual, X
#: series specifications, Physical Connection: "8bit, 1stop, No Parity").
BITS_PER_BYTE = 10
#: Return Delay Time (9) unit, seconds (e-manual, X-series control table: 2 [μsec]).
RETURN_DELAY_UNIT_S = 2e-6
#: A Protocol 2.0 packet's header and reserved byte. Byte stuffing keeps ``FF FF FD`` out of a
#: packet's body, so each occurrence in the stream starts a packet.
HEADER = b"\xff\xff\xfd\x00"


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
        self._tail = bytearray()  # the end of what was read, a header maybe cut in two

    def sent(self, data: bytes) -> None:
        """The host wrote ``data``: its bytes cross the wire before any servo acts on them."""
        self.clock.sleep(wire_time_s(len(data), self._baud()))

    def heard(self, data: bytes) -> None:
        """The host read ``data``: its bytes' wire time, and the Return Delay Time of each
        status packet that starts in it (a Sync Read's servos answer one after another, each
        after its own delay, as the e-manual's Sync Read describes)."""
        if not data:
            return
        delay = 0.0
        buf = self._tail + data
        while (i := buf.find(HEADER)) >= 0 and i + 5 <= len(buf):
            delay += return_delay_s(self._servos, buf[i + 4])
            del buf[: i + 5]
        self._tail = buf[-(len(HEADER)) :] if len(buf) > len(HEADER) else buf
        self.clock.sleep(delay + wire_time_s(len(data), self._baud()))

    def cleared(self) -> None:
        """The host discarded what had arrived: a packet cut short there starts no other."""
        self._tail.clear()
