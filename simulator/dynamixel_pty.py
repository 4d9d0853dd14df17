"""Emulated Dynamixel servos served on a pseudo-terminal, on a link that cannot race the host.

The official SDK decides that a servo is silent when no status packet has arrived within about
34 ms of *wall* time (``LATENCY_TIMER * 2 + 2`` ms plus the bytes' wire time), measured in a
busy loop. A real servo answers within its Return Delay Time (500 µs by default) plus the
packet's wire time, so the window is right for hardware. An emulator on a pty is a thread of the
host's own process: it must get a CPU *and* the GIL (which the SDK's busy loop holds) within
that window, so on a loaded machine an emulated servo that is present "times out" — the host and
the device model race each other in wall time, which no real bus does.

:class:`PtyServoServer` with :meth:`PtyServoServer.port_handler` removes the race instead of
widening the window. The host side is the SDK's own ``PortHandler`` (real pyserial on the pty,
the SDK's packet code unchanged) with its clock replaced by causality: a shared
:class:`LinkLedger` counts the bytes that crossed the pty in each direction, and a reply wait
ends in ``COMM_RX_TIMEOUT`` exactly when the emulator has taken every byte the host sent, has
answered all it is going to answer, and the host has consumed every byte answered — when no
more bytes can come, which is what a timeout on a real bus means. A present servo therefore
never times out however slow the machine, a silent one times out at once (no busy wait), and
no test depends on CPU load.

Return Delay Time is modelled causally too: a status packet is put on the wire only once the
host listens (reads) after sending. That is the worst case of a real host, which sends its next
instruction well within the 500 µs delay: a status the SDK does not read (unicast ``*TxOnly``
or Action) therefore always arrives *after* the next instruction's ``clearPort`` and is taken as
its answer — the SDK pitfall the driver must handle, reproduced every time instead of by luck.

A plain ``dynamixel_sdk.PortHandler`` opened on :attr:`PtyServoServer.device_path` (or any other
client) still works: without a ledger, replies are written in real time after
each servo's own Return Delay Time (address 9) plus the packet's wire time at the host's
baud rate (:func:`real_time_replies`), counted from when the instruction was read (as a servo
counts from its last byte), and the SDK's wall-time timeout applies.
"""

from __future__ import annotations

import contextlib
import os
import select
import sys
import threading
import time
import tty
from collections.abc import Callable
from typing import Any

import dynamixel_sdk

from rti_rig.core.clock import Clock
from rti_rig.core.deferred_signals import signals_deferred
from rti_rig.simulator.dynamixel_bus_time import BusTime, return_delay_s, wire_time_s
from rti_rig.simulator.dynamixel_emulator import DynamixelBusEmulator
from rti_rig.simulator.pty_link import HostBaudDevice, host_baud

#: Wall-time bound on a reply wait that is still *not* causally over (bytes lost in the kernel,
#: a wedged emulator thread): a broken link fails a test in bounded time instead of hanging it.
#: Never reached while the emulator thread runs, however loaded the machine.
LOST_LINK_S = 30.0

#: How long the host sleeps (GIL released) between checks while a reply is on its way; it
#: wakes at once when bytes arrive.
HOST_WAIT_S = 0.002


class LinkLedger:
    """What has crossed the pty, in bytes, each way; shared by the server and the host's port.

    ``host_sent``: written by the host; ``device_read``: taken *and handled* by the emulator;
    ``device_sent``: status bytes put on the wire; ``host_got``: consumed by the host (read or
    discarded by ``clearPort``). ``held``: statuses waiting for the host to listen."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        #: notified (``lock`` held) as the emulator has handled more of what the host sent
        self.handled = threading.Condition(self.lock)
        self.host_sent = 0
        self.device_read = 0
        self.device_sent = 0
        self.host_got = 0
        self.listening = False
        self.held: list[bytes] = []

    def quiet(self) -> bool:
        """No more bytes can reach the host until it sends again (call with ``lock`` held)."""
        return (
            not self.held
            and self.device_read >= self.host_sent
            and self.host_got >= self.device_sent
        )


def real_time_replies(
    emulator: DynamixelBusEmulator, reply: bytes, baud: int | None, heard: int = 0
) -> list[tuple[float, bytes]]:
    """Each status packet of ``reply`` with the wall time to wait before it is complete on
    the wire: its servo's Return Delay Time (9, 2 µs units, as that servo's table holds it
    now), then its bytes at ``baud`` (no wire time when the host's rate is unknown). Several
    packets (a Sync Read's) follow one another, each servo waiting its own delay. The first
    also waits for the ``heard`` instruction bytes to cross the wire (a servo answers a
    packet it has received whole; the host's write to the pty is instant).

    Why: replies to a plain ``PortHandler`` had come after a fixed 0.5 ms whatever the servo's
    Return Delay Time, and at no wire speed, so a host rehearsing against the served pty met
    a faster bus than its own (a 15-byte status takes 2.6 ms at the factory 57600 baud)."""
    out: list[tuple[float, bytes]] = []
    i = 0
    while i + 7 <= len(reply):
        n = 7 + int.from_bytes(reply[i + 5 : i + 7], "little")  # header, id, LEN, then LEN
        packet = reply[i : i + n]
        delay = return_delay_s(emulator.servos, reply[i + 4])
        wire = wire_time_s(len(packet) + (heard if not out else 0), baud)
        out.append((delay + wire, packet))
        i += n
    if i < len(reply):  # not a whole packet: sent as it is, at once
        out.append((0.0, reply[i:]))
    return out


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        view = view[n:]


class PtyServoServer:
    """Serve an emulator on a pseudo-terminal; ``start()`` returns the device path
    (e.g. /dev/pts/5); :meth:`port_handler` gives the SDK port to use on it.

    A slave fd stays open for the server's lifetime (otherwise reads fail with EIO whenever the
    SDK closes its port); ``stop()`` joins the thread within a bounded time.

    Clients without a ledger (a plain ``PortHandler``) get their replies in real time, as
    :func:`real_time_replies` paces them (``real_time = False``: at once), counted from the
    moment the instruction was read (``monotonic``, ``sleep``: the wall clock the pacing
    reads and waits on, a test's own where it checks the pacing)."""

    def __init__(
        self,
        emulator: DynamixelBusEmulator,
        poll_s: float = 0.02,
        real_time: bool = True,
        monotonic: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.emulator = emulator
        self._monotonic = monotonic
        self._sleep = sleep
        # told the host's line speed where it declares it (decided once, as pty_link's
        # server decides: a runtime protocol's isinstance walks its members each time)
        self.host_baud_device = emulator if isinstance(emulator, HostBaudDevice) else None
        self.poll_s = poll_s
        self.real_time = real_time
        self.device_path: str | None = None
        self.ledger: LinkLedger | None = None
        self._fds: tuple[int, int] | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> str:
        master, slave = os.openpty()
        tty.setraw(slave)
        self._fds = (master, slave)
        self.device_path = os.ttyname(slave)
        self._stop.clear()
        self._thread = threading.Thread(target=self._serve, name="dxl-emulator", daemon=True)
        self._thread.start()
        return self.device_path

    def port_handler(self, clock: Clock | None = None) -> EmulatedLinkPortHandler:
        """The SDK's ``PortHandler`` on this pty, with causal reply timeouts (module docstring),
        charging ``clock`` (the emulator's unless given) with the bus's time
        (:class:`~rti_rig.simulator.dynamixel_bus_time.BusTime`).

        From the first call on, replies follow the ledger (held until the host listens)."""
        if self.device_path is None:
            raise RuntimeError("start() the server before asking for its port")
        if self.ledger is None:
            self.ledger = LinkLedger()
        return EmulatedLinkPortHandler(self.device_path, self, clock)

    def send(self, data: bytes) -> None:
        """Put status bytes on the wire (call with the ledger's lock held)."""
        assert self._fds is not None and self.ledger is not None
        self.ledger.device_sent += len(data)
        with contextlib.suppress(OSError):
            _write_all(self._fds[0], data)

    def _serve(self) -> None:
        assert self._fds is not None
        master = self._fds[0]
        while not self._stop.is_set():
            ready, _, _ = select.select([master], [], [], self.poll_s)
            if not ready:
                continue
            try:
                data = os.read(master, 4096)
            except OSError:
                continue
            # the instruction's last byte is here now: a real servo's Return Delay Time runs
            # from this moment, not from when this thread gets round to answering
            read_at = self._monotonic()
            # the line speed the host set on its end (a pty pair shares its termios), as the
            # servos hear it: one at another Baud Rate answers nothing
            if self.host_baud_device is not None:
                self.host_baud_device.host_baud = host_baud(master)
            reply = self.emulator.receive(data)
            ledger = self.ledger
            if ledger is None and (late := self.emulator.take_late()) is not None:
                # a plain port: the late status after its delay, in time
                self._write_paced(master, [late], read_at)
            if ledger is not None:
                with ledger.lock:
                    ledger.device_read += len(data)
                    ledger.handled.notify_all()
                    if reply and ledger.listening:
                        self.send(reply)
                    elif reply:
                        ledger.held.append(reply)
                continue
            if not reply:
                continue
            if not self.real_time:
                with contextlib.suppress(OSError):
                    _write_all(master, reply)
                continue
            baud = self.emulator.host_baud
            self._write_paced(
                master, real_time_replies(self.emulator, reply, baud, len(data)), read_at
            )

    def _write_paced(self, fd: int, paced: list[tuple[float, bytes]], read_at: float) -> None:
        """Write each ``(wait s, bytes)`` of ``paced`` (:func:`real_time_replies`) once its
        wait, added to the ones before it, has passed since ``read_at`` (when the instruction
        was read); one already due is written at once.

        Why: each wait had been slept after the emulator had handled the instruction, so a
        thread that was itself late (a loaded host, the GIL) answered that much later than
        the Return Delay Time (ROBOTIS e-manual, Return Delay Time (9): 2 µs units, 250 =
        500 µs), which a real servo counts from the instruction's last byte. Emulator thread
        only; tests inject ``sleep``."""
        due = read_at
        for wait_s, packet in paced:
            due += wait_s
            left = due - self._monotonic()
            if left > 0:
                self._sleep(left)
            with contextlib.suppress(OSError):
                _write_all(fd, packet)

    def stop(self, timeout_s: float = 1.0) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout_s)
            self._thread = None
        if self._fds is not None:
            for fd in self._fds:
                with contextlib.suppress(OSError):
                    os.close(fd)
            self._fds = None

    def __enter__(self) -> PtyServoServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


class EmulatedLinkPortHandler(dynamixel_sdk.PortHandler):
    """``dynamixel_sdk.PortHandler`` whose reply timeout is causal, not wall time.

    Everything else is the SDK's own (pyserial on the pty, baud checks, packet timing
    bookkeeping). Counts every byte in and out in the server's :class:`LinkLedger`.

    ``clock`` (the emulator's unless given) is charged the bus's time as the host meets it
    (:class:`~rti_rig.simulator.dynamixel_bus_time.BusTime`): the ledger hands a status over as
    soon as the host listens, and a dry run had paid no wire time nor Return Delay Time."""

    def __init__(self, port_name: str, server: PtyServoServer, clock: Clock | None = None) -> None:
        super().__init__(port_name)
        assert server.ledger is not None
        self._server = server
        self._ledger = server.ledger
        self.bus_time = BusTime(
            clock if clock is not None else server.emulator.clock,
            server.emulator.servos,
            self.getBaudRate,
        )

    def _listen(self) -> None:
        ledger = self._ledger
        with ledger.lock:
            if not ledger.listening:
                ledger.listening = True
                if ledger.held:
                    data = b"".join(ledger.held)
                    ledger.held.clear()
                    self._server.send(data)

    def closePort(self) -> None:
        """Close after the link has settled: statuses the host never read are lost with the
        port, as on a real adapter (they would have arrived within 0.5 ms, before any reopen)."""
        if self.is_open and self.ser is not None:
            self._settle()
        super().closePort()

    def _settle(self) -> None:
        """Wait until the emulator has handled every byte sent, drop what it holds, and
        discard what reached the port unread (bounded by :data:`LOST_LINK_S`)."""
        ledger = self._ledger
        deadline = time.monotonic() + LOST_LINK_S
        while time.monotonic() < deadline:
            with ledger.lock:
                if ledger.device_read >= ledger.host_sent:
                    ledger.held.clear()
                    self._server.emulator.take_late()
                    if ledger.host_got >= ledger.device_sent:
                        ledger.listening = False
                        return
            if self.ser.in_waiting:
                self._take_waiting()
            else:
                select.select([self.ser.fileno()], [], [], HOST_WAIT_S)

    def setupPort(self, cflag_baud: Any) -> bool:
        ok = super().setupPort(cflag_baud)  # closes (settled) if open; flushes the input
        ledger = self._ledger
        with ledger.lock:
            ledger.held.clear()
            ledger.host_got = max(ledger.host_got, ledger.device_sent)
            ledger.listening = False
        return ok

    def clearPort(self) -> None:
        """Discard what has arrived (``reset_input_buffer``), counting it as consumed."""
        ledger = self._ledger
        with ledger.lock:
            ledger.listening = False
            self._server.emulator.take_late()  # arrived before the clear: discarded too
        self._take_waiting()
        self.bus_time.cleared()

    def _take_waiting(self) -> None:
        """Read and drop what has arrived, counted as consumed (as one step: see
        :meth:`writePort`)."""
        with signals_deferred():
            waiting = self.ser.in_waiting
            data = self.ser.read(waiting) if waiting else b""
            with self._ledger.lock:
                self._ledger.host_got += len(data)

    def writePort(self, packet: Any) -> int:
        """The SDK's write, and its bytes counted in the ledger, as one step: SIGINT/SIGTERM
        are held over the two (:func:`signals_deferred`; a pty write of a packet is a few
        microseconds) and acted on right after.

        Why: the CLI's emergency stop is raised wherever its signal lands, and one landing
        between pyserial's write and the count left ``host_sent`` short of what the emulator
        read; every later reply wait then ended as soon as the emulator had read as many
        bytes as the host had counted, before it had read the new instruction, and the run's
        teardown said the servos were "asked again 2 times after a status packet was lost",
        no packet having been. A stop between a read and its count left ``host_got`` short:
        each later wait for a silent servo lasted :data:`LOST_LINK_S`. The link's bookkeeping
        is this emulator's, not the device's; the stop still lands mid-exchange (after the
        write, before the reply is read) as on a real bus, for the driver to recover from."""
        ledger = self._ledger
        with signals_deferred():
            with ledger.lock:
                ledger.listening = False
            self.bus_time.sent(bytes(packet))  # the servos act once its last byte is in
            n = super().writePort(packet)
            with ledger.lock:
                ledger.host_sent += int(n or 0)
        self._handled()
        return n

    def _handled(self) -> None:
        """Wait until the emulator has handled every byte sent (bounded by
        :data:`LOST_LINK_S`), as the in-process port's write does.

        Why: the emulator reads the clock as it handles an instruction, and the host charges
        the clock with the bus's time (the next instruction's bytes, a poll's sleep) right
        after a write it reads no status for (a Sync Write): the two raced, so a goal started
        a few milliseconds late or not, and a dry run's session time varied from run to run
        (30.14 or 30.17 s for one plan). Waiting on the thread's notice costs no busy loop."""
        ledger = self._ledger
        with ledger.handled:
            ledger.handled.wait_for(
                lambda: ledger.device_read >= ledger.host_sent, timeout=LOST_LINK_S
            )

    def readPort(self, length: int) -> bytes:
        """The SDK's read and its count as one step (see :meth:`writePort`)."""
        self._listen()
        with signals_deferred():
            data = super().readPort(length)
            with self._ledger.lock:
                self._ledger.host_got += len(data)
        self.bus_time.heard(bytes(data))
        return data

    def setPacketTimeout(self, packet_length: Any) -> None:
        """The SDK's window; the clock's wait for a status counts from here."""
        super().setPacketTimeout(packet_length)
        self.bus_time.window_opened()

    def setPacketTimeoutMillis(self, msec: Any) -> None:
        super().setPacketTimeoutMillis(msec)
        self.bus_time.window_opened()

    def isPacketTimeout(self) -> bool:
        """Causal (module docstring); the clock is charged what a real host waits: its whole
        window for a status that never comes or comes after it, a late one's lateness when it
        comes within (they had cost the clock nothing).

        Given up at :data:`LOST_LINK_S` of wall time (a broken link: the emulator never went
        quiet), the clock is still charged the window, not the lost-link limit: the SDK's own
        ``isPacketTimeout`` (dynamixel_sdk 4.1 port_handler.py) gives up once
        ``getTimeSinceStart() > packet_timeout``, the window ``setPacketTimeout`` opened, so
        that is all a real host waits; the limit is this emulator's bound on a test, not bus
        time."""
        self._listen()
        with self._ledger.lock:
            over = self._ledger.quiet()
            late = self._server.emulator.take_late() if over else None
            if late is not None:
                # a status on its way late (``delay_reply``, a slow link's): it comes, within
                # the host's window if that is the longer, else just after it ends
                self._server.send(late[1])
                over = late[0] * 1000.0 > self.packet_timeout
                if not over:
                    self.bus_time.waited(late[0] * 1000.0, gave_up=False)
        if over or self.getTimeSinceStart() > max(self.packet_timeout, LOST_LINK_S * 1000.0):
            self.bus_time.waited(self.packet_timeout, gave_up=True)
            self.packet_timeout = 0
            return True
        # a reply is on its way: sleep (GIL released) until bytes arrive, briefly
        with contextlib.suppress(OSError, ValueError):
            select.select([self.ser.fileno()], [], [], HOST_WAIT_S)
        return False


#: The manual tool that serves emulated servos on a pty (this module is the link it uses).
SERVE_TOOL = "python -m rti_rig.simulator.dynamixel_emulator"


def main(argv: list[str] | None = None) -> int:
    """Say which tool serves emulated servos: this module is the pty link, not a tool.

    Why: its name reads like the arm's pty emulator, and ``python -m
    simulator.dynamixel_pty --help`` printed nothing and exited 0, leaving the user with no
    port and no pointer to the tool that gives one."""
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m rti_rig.simulator.dynamixel_pty",
        usage=f"{SERVE_TOOL} [--config RIG.toml] [--seconds S] [--baud BAUD] "
        "[--fault K:KIND[:ID]]  (see its --help)",
        description="This module is the pseudo-terminal link the emulated servos are served "
        f"on (a library for the tests and dry runs); it serves nothing by itself. To serve a "
        f"rig config's arm servos on a pty, run {SERVE_TOOL} (docs/protocols/dynamixel-arm.md).",
    )
    # the tool's own options (--config …) given here are not this module's: one answer for all
    parser.parse_known_args(argv)
    parser.print_usage(sys.stderr)
    print(
        f"this module serves nothing by itself: run {SERVE_TOOL} (with the same options) to "
        "serve emulated servos",
        file=sys.stderr,
    )
    return 2


if __name__ == "__main__":
    raise SystemExit(main())
