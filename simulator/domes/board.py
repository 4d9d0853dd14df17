"""A microcontroller board running a dome firmware, in time: the base of every firmware emulator.

Each firmware is written as a generator in its own module, from its published behaviour, the
way its sketch reads: ``yield Read()`` waits for a byte (``Read(timeout)`` like a Stream
timeout, ``peek=True`` leaves the byte in the buffer), ``yield Sleep(s)`` blocks like
``delay()``, :meth:`Board.print` queues output that leaves the UART at the baud rate. The board
runs the firmware on the injected clock (``SystemClock`` on a pty, where real pyserial talks to
it; a ``VirtualClock`` in-process), so blocking and framing by silence behave as on the board.

What the board models besides the firmware:

* **auto-reset on open** (Arduinos whose DTR resets them): the firmware restarts after
  ``boot_s`` in the bootloader; bytes received meanwhile are lost;
* a 64-byte receive buffer (bytes past it are dropped, as on an AVR Arduino);
* **the truth**: :attr:`timeline` records which LEDs are lit from every moment on, so a test
  asserts what the dome did, not what the driver said;
* faults keyed by the n-th command the firmware starts executing (:meth:`begin_command`):
  reply lost, garbled or late, a reset instead of the command, the USB port gone.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Generator
from dataclasses import dataclass

from rti_rig.core.clock import Clock, SystemClock
from rti_rig.simulator.dome_firmware import Fault, FaultKind, FaultPlan, Output, garble
from rti_rig.simulator.pty_link import HostBaudDevice, TickingDevice

RX_BUFFER = 64

#: The faults a board applies (:meth:`Board.begin_command`); a firmware's emulator has no
#: other (a command damaged on the way in, a reset after the reply are the project's own
#: protocols' emulator's), so asking one of it for another is refused, not silently ignored.
BOARD_FAULT_KINDS = (
    FaultKind.DROP_REPLY,
    FaultKind.GARBLE_REPLY,
    FaultKind.DELAY_REPLY,
    FaultKind.RESET,
    FaultKind.DISCONNECT,
)


@dataclass(frozen=True)
class Sleep:
    seconds: float


@dataclass(frozen=True)
class Read:
    """Wait for a byte (None: forever); the value sent back is the byte or None on timeout."""

    timeout_s: float | None = None
    peek: bool = False


Firmware = Generator[Sleep | Read, int | None, None]


class Board(HostBaudDevice, TickingDevice):
    """A board with LEDs running :meth:`firmware`; serve it with ``serve_on_pty``, which tells
    it the host's UART rate and ticks its clock (the two capabilities it declares)."""

    name = "board"
    led_count = 0
    baudrate = 9600
    #: Seconds in the bootloader after a reset (bytes received meanwhile are lost).
    boot_s = 0.0
    #: Opening the port resets the board (Arduino DTR auto-reset).
    resets_on_open = True
    #: The board's serial port is the microcontroller's own USB (CDC ACM, e.g. an ATmega32u4):
    #: no UART lies between host and firmware, so the host's baud rate is a setting nobody
    #: reads and any rate works. Behind a USB-serial chip (FTDI, 16U2) both UARTs must agree.
    native_usb = False
    #: The host's baud rate at which closing the port drops the board into its bootloader (the
    #: ATmega32u4 core's "1200-baud touch": line rate 1200, then DTR low); None: no such rate.
    bootloader_touch_baud: int | None = None
    #: Seconds such a bootloader waits for an upload before it starts the sketch again
    #: (Caterina: 8 s); bytes sent meanwhile never reach the sketch.
    bootloader_wait_s = 8.0
    #: The firmware switches its LEDs on its own clock, with no command (RTIPy's LED goes dark
    #: when its window ends): what is lit when the camera exposes depends on the time the rig
    #: spends between two commands, so a dry run must spend that time on the board's clock too
    #: (``rti_rig.app.compose`` then runs the whole rig on it). Elsewhere only commands change
    #: the LEDs, and the rig's simulated time may pass without the board's.
    self_timed = False

    def __init__(self, clock: Clock | None = None, faults: FaultPlan | None = None) -> None:
        self.clock = clock or SystemClock()
        self.faults = faults or FaultPlan()
        self._lock = threading.RLock()
        self._rx: deque[tuple[float, int]] = deque()
        self._out: list[Output] = []
        self._tx_free = 0.0
        self._gen: Firmware | None = None
        self._wait: Sleep | Read | None = None
        self._wait_start = 0.0
        self._boot_until = 0.0
        self.t = self.clock.now()
        self._lit: frozenset[int] = frozenset()
        #: (time, LEDs lit from then on), in order.
        self.timeline: list[tuple[float, frozenset[int]]] = [(self.t, frozenset())]
        #: (time, what): boots, camera pulses, faults, anything worth asserting.
        self.events: list[tuple[float, str]] = []
        self.commands = 0
        self.powered = False
        self._mode: Fault | None = None
        self._disconnect: float | None = None
        self._reset_pending = False
        self._unplugged = False
        self.heard = bytearray()  # every byte the firmware received (for tests)
        #: The host's UART speed (set by the pty server); at another speed than the board's,
        #: both sides read garbage, as two UARTs at different baud rates do.
        self.host_baud: int | None = None

    # ------------------------------------------------------------------ firmware side

    def firmware(self) -> Firmware:  # pragma: no cover - each firmware overrides it
        raise NotImplementedError
        yield

    def print(self, data: bytes | str) -> None:
        """Send ``data`` (paced at the baud rate, after anything already queued)."""
        raw = data.encode("latin-1") if isinstance(data, str) else data
        if self._baud_mismatch():
            raw = misread(raw)
        mode = self._mode
        if mode is not None and mode.kind is FaultKind.DROP_REPLY:
            return
        if mode is not None and mode.kind is FaultKind.GARBLE_REPLY:
            raw = garble(raw)
        start = max(self.t, self._tx_free)
        if mode is not None and mode.kind is FaultKind.DELAY_REPLY:
            start += mode.delay_s  # once: the rest of the reply follows it, in order
            self._mode = None
        due = start + len(raw) * 10.0 / self.baudrate
        self._tx_free = due
        self._out.append(Output(due, raw))

    def println(self, text: str = "") -> None:
        self.print(text + "\r\n")

    def set_lit(self, leds: frozenset[int] | set[int]) -> None:
        if self._unplugged:
            return  # no power: nothing lights, whatever the firmware's last steps would do
        lit = frozenset(i for i in leds if 0 <= i < self.led_count)
        if lit != self._lit:
            self._lit = lit
            self.timeline.append((self.t, lit))

    def event(self, what: str) -> None:
        self.events.append((self.t, what))

    def begin_command(self) -> bool:
        """Count a command the firmware starts; apply its fault. False: do not execute it."""
        self.commands += 1
        self._mode = None
        for fault in self.faults.at(self.commands):
            self.event(f"fault {fault.kind} at command {self.commands}")
            if fault.kind is FaultKind.RESET:
                self._reset_pending = True  # done once the running firmware yields
                return False
            if fault.kind is FaultKind.DISCONNECT:
                self._disconnect = fault.delay_s
                self._lit_off_unpowered()
                self._unplugged = True
                return False
            self._mode = fault
        return True

    # ------------------------------------------------------------------ truth

    @property
    def lit(self) -> frozenset[int]:
        """LEDs lit now (the firmware is first run up to now)."""
        with self._lock:
            self._advance(self.clock.now())
            return self._lit

    def lit_once_booted(self) -> frozenset[int]:
        """LEDs lit once a boot under way is over (the firmware run to the end of its
        bootloader, or up to now if later), with nothing more sent to it.

        Why: a board still in its bootloader has every pin low, so :attr:`lit` reads empty
        for a Nab board that a late opening reset and nobody switched off: it lights every LED
        in ``setup()`` the moment it leaves the bootloader. What a test of "the dome was left
        dark" must read, once the host has closed the port."""
        with self._lock:
            self._advance(max(self.clock.now(), self._boot_until))
            return self._lit

    def lit_at(self, t: float) -> frozenset[int]:
        with self._lock:
            state = frozenset[int]()
            for when, lit in self.timeline:
                if when > t:
                    break
                state = lit
            return state

    # ------------------------------------------------------------------ PtyDevice

    def on_port_opened(self) -> list[Output]:
        with self._lock:
            now = self.clock.now()
            self._advance(now)
            if self.resets_on_open or not self.powered:
                self._power_on(now)
            return self._take(now)

    def on_port_closed(self) -> None:
        """The host closed the port (its DTR dropped). At :attr:`bootloader_touch_baud` the
        board jumps to its bootloader: the sketch stops, and starts again from ``setup()``
        after :attr:`bootloader_wait_s`, as after a reset."""
        with self._lock:
            now = self.clock.now()
            self._advance(now)
            touch = self.bootloader_touch_baud
            if touch is None or self.host_baud != touch or not self.powered:
                return
            self._power_on(now, self.bootloader_wait_s)
            self.event("bootloader (1200-baud touch)")

    def receive(self, data: bytes) -> list[Output]:
        with self._lock:
            now = self.clock.now()
            self._advance(now)
            per_byte = 10.0 / self.baudrate
            if self._baud_mismatch():
                data = misread(data)
            for i, b in enumerate(data):
                t = now + i * per_byte
                if not self.powered or t < self._boot_until or len(self._rx) >= RX_BUFFER:
                    continue  # in the bootloader, unpowered, or the buffer is full: lost
                self._rx.append((t, b))
            self._advance(now)
            return self._take(now)

    def tick(self) -> list[Output]:
        with self._lock:
            now = self.clock.now()
            self._advance(now)
            return self._take(now)

    def take_disconnect(self) -> float | None:
        with self._lock:
            down, self._disconnect = self._disconnect, None
            if down is not None:
                self.powered = False
                self._gen = None
            return down

    # ------------------------------------------------------------------ internals

    def _baud_mismatch(self) -> bool:
        if self.native_usb:
            return False
        return self.host_baud is not None and self.host_baud != self.baudrate

    def _lit_off_unpowered(self) -> None:
        self.set_lit(frozenset())

    def _power_on(self, now: float, boot_s: float | None = None) -> None:
        self._unplugged = False
        self.t = now
        self.event("boot")
        self._rx.clear()
        self._out.clear()
        self._tx_free = now
        self._mode = None
        self.set_lit(frozenset())  # pins float low while in the bootloader
        self.powered = True
        boot = self.boot_s if boot_s is None else boot_s
        self._boot_until = now + boot
        self._gen = self.firmware()
        self._wait = Sleep(boot)
        self._wait_start = now

    def _take(self, now: float) -> list[Output]:
        out, self._out = self._out, []
        return out

    def _advance(self, until: float) -> None:
        while self._gen is not None:
            wait = self._wait
            if isinstance(wait, Sleep):
                end = self._wait_start + wait.seconds
                if end > until:
                    return
                self.t = max(self.t, end)
                self._resume(None)
            elif isinstance(wait, Read):
                if self._rx and self._rx[0][0] <= until:
                    t, b = self._rx[0] if wait.peek else self._rx.popleft()
                    if not wait.peek:
                        self.heard.append(b)
                    self.t = max(self.t, t)
                    self._resume(b)
                elif wait.timeout_s is not None and self._wait_start + wait.timeout_s <= until:
                    self.t = max(self.t, self._wait_start + wait.timeout_s)
                    self._resume(None)
                else:
                    return
            else:
                return

    def _resume(self, value: int | None) -> None:
        assert self._gen is not None
        try:
            self._wait = self._gen.send(value)
        except StopIteration:
            self._gen = None
            return
        self._wait_start = self.t
        if self._reset_pending:
            self._reset_pending = False
            self._power_on(self.t)


def misread(data: bytes) -> bytes:
    """What a UART at the wrong baud rate makes of ``data`` (deterministic garbage)."""
    return bytes((b ^ 0x5A) | 0x80 for b in data)


def atoi(text: str) -> int:
    """C ``atoi``: optional blanks and sign, then digits; anything else gives 0."""
    s = text.lstrip(" \t\r\n")
    sign = -1 if s[:1] == "-" else 1
    s = s[1:] if s[:1] in "+-" else s
    digits = ""
    for c in s:
        if not c.isdigit():
            break
        digits += c
    return sign * int(digits) if digits else 0


def c_div(a: int, b: int) -> int:
    """C integer division (truncates toward zero)."""
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b > 0) else -q


def c_mod(a: int, b: int) -> int:
    return a - b * c_div(a, b)
