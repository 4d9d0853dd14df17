"""An LED dome firmware emulator of rti-rig's own protocols, with deterministic faults.

The emulator reads commands and writes replies with its own reading of
docs/protocols/led-dome.md (:mod:`rti_rig.simulator.own_protocols`), never with the driver's
codecs: a codec bug shared by both sides would pass every test. The real driver runs against
it unchanged: in-process through
:class:`InProcessDomeTransport` on a virtual clock, or over a pseudo-terminal through real
pyserial (``rti_rig.simulator.pty_link.emulated_dome_on_pty``).

It keeps the **truth**: :attr:`DomeFirmware.lit` is the LED that really emits light (after dead
LEDs, the watchdog, resets and dropped commands), so a simulated camera can render what the
firmware does, not what the host asked for, and tests can check that no image is ever recorded
under a wrong light.

Faults come from a :class:`FaultPlan` keyed by the number of the command received (1-based,
counted over the emulator's whole life, garbled commands included), so a test can say "drop the
reply to the 5th command" and get the same run every time.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from enum import StrEnum

from rti_rig.core.clock import Clock, SystemClock
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.drivers.led_dome.transport import TransportError
from rti_rig.simulator.own_protocols import (
    BAD_ARGUMENT,
    LED_FAULT,
    LED_OUT_OF_RANGE,
    BinaryProfile,
    BoardFacts,
    DefaultProfile,
    FramedProfile,
    OwnCodec,
    Refused,
    Request,
    Verb,
)
from rti_rig.simulator.pty_link import PtyLink, serve_on_pty, sigterm_as_ctrl_c


class FaultKind(StrEnum):
    DROP_REPLY = "drop_reply"  # executed, reply never sent
    GARBLE_REPLY = "garble_reply"  # executed, one reply byte damaged
    GARBLE_COMMAND = "garble_command"  # one command byte damaged on the way in
    DELAY_REPLY = "delay_reply"  # executed, reply sent after ``delay_s``
    DISCONNECT = "disconnect"  # USB drop as the command arrives: not executed, board unpowered
    RESET = "reset"  # brown-out reset as the command arrives: not executed, banner
    RESET_AFTER_REPLY = "reset_after_reply"  # executed and acknowledged, then a reset
    #: executed, its reply preceded by a stray CR LF (an Arduino sketch's Serial.println()
    #: after its banner, or a host line ending echoed back); line profiles only (default,
    #: framed): on the binary link those bytes would be two acknowledgements
    BLANK_LINE_BEFORE_REPLY = "blank_line_before_reply"


@dataclass(frozen=True)
class Fault:
    """Fault ``kind`` at the ``at_command``-th command received (1-based)."""

    at_command: int
    kind: FaultKind
    delay_s: float = 1.0  # DELAY_REPLY: reply delay; DISCONNECT: time the device stays away


@dataclass(frozen=True)
class FaultPlan:
    faults: tuple[Fault, ...] = ()

    @classmethod
    def of(cls, *faults: tuple[int, FaultKind] | Fault) -> FaultPlan:
        return cls(tuple(f if isinstance(f, Fault) else Fault(f[0], f[1]) for f in faults))

    def at(self, n: int) -> list[Fault]:
        return [f for f in self.faults if f.at_command == n]


@dataclass(frozen=True)
class Output:
    """Bytes the board sends at time ``due_s`` (on the emulator's clock)."""

    due_s: float
    data: bytes


@dataclass
class _LitLed:
    index: int
    level: int
    since: float
    until: float | None  # watchdog deadline


@dataclass
class FirmwareEvent:
    """One entry of the truth log."""

    time_s: float
    what: str  # "boot", "lit", "off", "watchdog", "shutter", "reset", "unplugged", "dead"
    index: int | None = None
    level: int | None = None


def garble(data: bytes) -> bytes:
    """Damage one byte in the middle of ``data`` (deterministic, keeps a trailing newline)."""
    if not data:
        return data
    body_len = len(data) - 1 if data.endswith(b"\n") and len(data) > 1 else len(data)
    i = body_len // 2
    return data[:i] + bytes([data[i] ^ 0x41]) + data[i + 1 :]


#: An Arduino-like board's time in its bootloader after the reset an opening of its port causes
#: (DTR), before the sketch prints its banner: what the board served on a pty by this module's
#: command line has, and what a board that resets on open must have there. With none, the
#: banner was written to the pty the moment the host's open() reached the device node, before
#: pyserial's own open had ended: its flush of the input queue (``tcflush``, the last step of
#: ``Serial.open``) then discarded it whenever the host was descheduled in between, as on a
#: loaded machine (a probe heard the banner at 9600 baud and "(nothing)" at 115200). A real
#: board's banner comes after its boot, long after the host's open has returned.
RESET_BOOT_S = 0.5


@dataclass
class DomeFirmware:
    """The board: LEDs, a watchdog, a boot banner, and the faults of its plan.

    ``reports_dead_leds``: the board senses LED current and answers an error for a dead LED;
    otherwise it acknowledges and the LED stays dark (only the image can tell).
    """

    codec: OwnCodec
    led_count: int = 48
    firmware_id: str = "RTIDOME-EMU"
    version: str = "1.0.0"
    max_level: int = 255
    dead_leds: frozenset[int] = frozenset()
    reports_dead_leds: bool = True
    faults: FaultPlan = field(default_factory=FaultPlan)
    clock: Clock = field(default_factory=SystemClock)
    boot_delay_s: float = 0.0
    banner_on_boot: bool = True
    #: Serial line speed: replies take the time their bytes (and the command's) need on the
    #: wire, 10 bits a byte, as a UART would; a pty alone has no line speed. None: instant.
    baudrate: int | None = None

    def __post_init__(self) -> None:
        self.dead_leds = frozenset(self.dead_leds)
        self._lock = threading.RLock()
        self._rx = bytearray()
        self._lit: _LitLed | None = None
        self.commands_received = 0
        self.history: list[FirmwareEvent] = []
        self.powered = False
        self.unplugged_until: float | None = None
        self._disconnect_pending: float | None = None
        self._booting_until = 0.0

    @property
    def identity(self) -> BoardFacts:
        return BoardFacts(self.firmware_id, self.version, self.led_count)

    def wire_s(self, n_bytes: int) -> float:
        """Seconds ``n_bytes`` take on the serial line (8N1: 10 bits a byte)."""
        return 0.0 if not self.baudrate else n_bytes * 10.0 / self.baudrate

    # ------------------------------------------------------------------ truth

    @property
    def lit(self) -> tuple[int, int] | None:
        """(index, level) of the LED really emitting light now, or None."""
        with self._lock:
            self._expire_watchdog()
            lit = self._lit
            if lit is None or lit.index in self.dead_leds:
                return None  # a dead LED the firmware believes lit gives no light
            return (lit.index, lit.level)

    def lit_indices(self) -> list[int]:
        """LEDs really emitting light (0 or 1 of them: the firmware lights one at a time)."""
        state = self.lit
        return [] if state is None else [state[0]]

    # ------------------------------------------------------------------ lifecycle

    def boot(self) -> list[Output]:
        """Power-on or reset: everything off, banner after the boot delay."""
        with self._lock:
            now = self.clock.now()
            self._switch_off(now, "boot")
            self._rx.clear()
            self.powered = True
            self._booting_until = now + self.boot_delay_s
            self.history.append(FirmwareEvent(now, "boot"))
            if not self.banner_on_boot:
                return []
            banner = self.codec.banner(self.identity)
            return [Output(now + self.boot_delay_s + self.wire_s(len(banner)), banner)]

    def on_port_opened(self) -> list[Output]:
        """Opening the port toggles DTR, which resets an Arduino: reboot."""
        return self.boot()

    def on_port_closed(self) -> None:
        """The host closed the port: this Arduino sketch does nothing on its DTR dropping (only
        the open's DTR edge resets it, :meth:`on_port_opened`)."""

    def take_disconnect(self) -> float | None:
        """Seconds the device stays away, once, after a DISCONNECT fault fired; else None."""
        with self._lock:
            down, self._disconnect_pending = self._disconnect_pending, None
            return down

    def receive(self, data: bytes) -> list[Output]:
        """Bytes from the host; returns what the board sends back, with due times."""
        out: list[Output] = []
        with self._lock:
            if not self.powered:
                return out
            if self.clock.now() < self._booting_until:
                # the bootloader runs: bytes sent before the banner are lost, as on an Arduino
                self.history.append(FirmwareEvent(self.clock.now(), "lost while booting"))
                return out
            self._rx.extend(data)
            while self._rx and self.powered:
                parsed, consumed = self.codec.decode(bytes(self._rx))
                if parsed is None:
                    if consumed:
                        del self._rx[:consumed]
                        continue
                    break
                raw = bytes(self._rx[:consumed])
                del self._rx[:consumed]
                self.commands_received += 1
                faults = self.faults.at(self.commands_received)
                kinds = {f.kind for f in faults}
                if FaultKind.GARBLE_COMMAND in kinds:
                    reparsed, _ = self.codec.decode(garble(raw))
                    parsed = (
                        reparsed
                        if reparsed is not None
                        else Refused(raw, None, BAD_ARGUMENT, "garbled beyond framing")
                    )
                out += self._handle(parsed, faults, len(raw))
            return out

    # ------------------------------------------------------------------ internals

    def _handle(
        self,
        parsed: Request | Refused,
        faults: Iterable[Fault],
        command_len: int,
    ) -> list[Output]:
        now = self.clock.now()
        by_kind = {f.kind: f for f in faults}
        if FaultKind.DISCONNECT in by_kind:
            self._switch_off(now, "unplugged")
            self.history.append(FirmwareEvent(now, "unplugged"))
            self.powered = False
            down = by_kind[FaultKind.DISCONNECT].delay_s
            self.unplugged_until = now + down
            self._disconnect_pending = down
            return []
        if FaultKind.RESET in by_kind:
            self.history.append(FirmwareEvent(now, "reset"))
            return self.boot()
        if isinstance(parsed, Refused):
            data = self.codec.err(parsed.seq, parsed.code, parsed.text)
        else:
            data = self._execute(parsed, now)
        sent = now + self.wire_s(command_len + len(data))
        if FaultKind.DROP_REPLY in by_kind:
            out: list[Output] = []
        elif FaultKind.GARBLE_REPLY in by_kind:
            out = [Output(sent, garble(data))]
        elif FaultKind.DELAY_REPLY in by_kind:
            out = [Output(sent + by_kind[FaultKind.DELAY_REPLY].delay_s, data)]
        elif FaultKind.BLANK_LINE_BEFORE_REPLY in by_kind:
            out = [Output(sent, b"\r\n" + data)]
        else:
            out = [Output(sent, data)]
        if FaultKind.RESET_AFTER_REPLY in by_kind:
            self.history.append(FirmwareEvent(now, "reset"))
            # the reset follows the acknowledgement on the wire, whatever the boot delay
            out += [Output(max(o.due_s, sent + 1e-6), o.data) for o in self.boot()]
        return out

    def _execute(self, req: Request, now: float) -> bytes:
        """Run ``req`` and return the board's answer (acknowledgement or error) in bytes."""
        if req.verb is Verb.LIGHT:
            if not 0 <= req.index < self.led_count:
                text = f"LED {req.index} of {self.led_count}"
                return self.codec.err(req.seq, LED_OUT_OF_RANGE, text)
            if not 0 <= req.level <= self.max_level:
                return self.codec.err(req.seq, BAD_ARGUMENT, f"level {req.level}")
            self._switch_off(now, "off")
            if req.index in self.dead_leds:
                self.history.append(FirmwareEvent(now, "dead", req.index, req.level))
                if self.reports_dead_leds:
                    return self.codec.err(req.seq, LED_FAULT, f"LED {req.index} open circuit")
            until = None if not req.max_on_ms else now + req.max_on_ms / 1000.0
            self._lit = _LitLed(req.index, req.level, now, until)
            self.history.append(FirmwareEvent(now, "lit", req.index, req.level))
        elif req.verb is Verb.ALL_OFF:
            self._switch_off(now, "off")
        elif req.verb is Verb.SHUTTER:
            self.history.append(FirmwareEvent(now, "shutter", level=req.pulse_ms))
        elif req.verb is Verb.QUERY:
            self._expire_watchdog()
        lit = None if self._lit is None else (self._lit.index, self._lit.level)
        return self.codec.ok(req, self.identity, lit)

    def _expire_watchdog(self) -> None:
        lit = self._lit
        if lit is not None and lit.until is not None and self.clock.now() >= lit.until:
            self.history.append(FirmwareEvent(lit.until, "watchdog", lit.index))
            self._lit = None

    def _switch_off(self, now: float, why: str) -> None:
        self._expire_watchdog()
        if self._lit is not None:
            self.history.append(FirmwareEvent(now, why, self._lit.index))
        self._lit = None


class InProcessDomeTransport:
    """A :class:`rti_rig.drivers.led_dome.transport.Transport` wired straight to a
    :class:`DomeFirmware`.

    Reads wait on the firmware's (virtual) clock: a reply due later than the read's timeout is not
    seen, exactly like a late reply on a real port, but no test ever really sleeps.
    """

    #: Every opening reboots the firmware (:meth:`DomeFirmware.on_port_opened`, an Arduino's
    #: DTR auto-reset), as a serial device's does.
    resets_on_open = True

    def __init__(self, firmware: DomeFirmware, name: str = "in-process dome") -> None:
        self.firmware = firmware
        self.clock = firmware.clock
        self.name = name
        self._queue: list[Output] = []
        self._open = False
        self.opens = 0

    def open(self) -> None:
        fw = self.firmware
        now = self.clock.now()
        if fw.unplugged_until is not None and now < fw.unplugged_until:
            raise TransportError(f"{self.name}: no such device (unplugged)")
        self._open = True
        self.opens += 1
        self._queue = list(fw.on_port_opened())

    def close(self) -> None:
        self._open = False
        self._queue.clear()

    def write(self, data: bytes) -> None:
        self._check()
        self._queue += self.firmware.receive(data)
        self._queue.sort(key=lambda o: o.due_s)

    def read(self, timeout_s: float) -> bytes:
        self._check()
        now = self.clock.now()
        if not any(o.due_s <= now for o in self._queue):
            upcoming = [o.due_s for o in self._queue if o.due_s <= now + timeout_s]
            wait = (min(upcoming) - now) if upcoming else timeout_s
            if wait > 0:
                self.clock.sleep(wait)
            self._check()
            now = self.clock.now()
        ready = [o for o in self._queue if o.due_s <= now]
        self._queue = [o for o in self._queue if o.due_s > now]
        return b"".join(o.data for o in ready)

    def _check(self) -> None:
        if not self._open:
            raise TransportError(f"{self.name} is not open")
        down = self.firmware.take_disconnect()
        if down is not None or not self.firmware.powered:
            self._open = False
            self._queue.clear()
            raise TransportError(f"{self.name}: device disconnected")


def own_codec_for(settings: DomeSerialSettings) -> OwnCodec:
    """The emulator's own reading of the profile of ``settings``, with its options."""
    if settings.profile == "default":
        checksum = True if settings.default is None else settings.default.checksum
        return DefaultProfile(checksum=checksum)
    if settings.profile == "framed":
        f = settings.framed
        if f is None:
            return FramedProfile(full_level=settings.max_level)
        return FramedProfile(
            start=f.start,
            end=f.end,
            separator=f.separator,
            codes=f.codes.model_dump(),
            index_base=f.index_base,
            send_level=f.send_level,
            sequence=f.sequence,
            ok_word=f.ok_word,
            err_word=f.err_word,
            ready_word=f.ready_word,
            full_level=settings.max_level,
        )
    if settings.profile == "binary":
        b = settings.binary
        return BinaryProfile() if b is None else BinaryProfile(b.start_byte, b.index_base)
    raise ValueError(
        f"profile '{settings.profile}' is a firmware's: its emulator is in rti_rig.simulator.domes"
    )


def firmware_for(settings: DomeSerialSettings, **kwargs: object) -> DomeFirmware:
    """A firmware emulator speaking the profile of ``settings`` (its own reading of the spec)."""
    kwargs.setdefault("baudrate", settings.baudrate)
    return DomeFirmware(own_codec_for(settings), max_level=settings.max_level, **kwargs)  # type: ignore[arg-type]


@contextlib.contextmanager
def emulated_dome_on_pty(firmware: DomeFirmware) -> Iterator[PtyLink]:
    """Serve ``firmware`` on a pseudo-terminal; ``link.port`` is the path for pyserial.

    The firmware must run on a :class:`SystemClock`: the pty thread times replies in real time.
    """
    if not isinstance(firmware.clock, SystemClock):
        raise ValueError("a firmware served on a pty needs a SystemClock (replies are real-time)")
    with serve_on_pty(firmware, "dome") as link:
        yield link


def main(argv: list[str] | None = None) -> int:
    """Serve an emulated dome on a pty until interrupted.

    Run as ``python -m rti_rig.simulator.dome_firmware``.

    Prints the port path, so that a rig config (or ``rti-rig check``, or ``rti-rig probe``) can
    be pointed at it for a dry run through the real driver and real pyserial. ``--profile``
    names one of the project's own protocols (``default``, ``framed``, ``binary``) or a real
    firmware whose emulator ``rti_rig.simulator.domes`` holds (``nab-rti-v1`` …): that one has
    the firmware's own LED count and baud rate, so ``--leds`` and ``--dead`` do not apply to it;
    ``--boot-delay-s`` sets its time in the bootloader after a reset (a slow or older
    bootloader: the banner then comes later than the profile's boot wait).
    """
    import argparse

    from rti_rig.simulator.domes import SERIAL_FIRMWARES

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument(
        "--profile",
        choices=["default", "framed", "binary", *SERIAL_FIRMWARES],
        default="default",
        help="one of the project's own protocols, or a real firmware (docs/domes.md)",
    )
    parser.add_argument("--leds", type=int, default=None, help="LED count (default 48)")
    parser.add_argument("--dead", type=int, nargs="*", default=[], help="dead LED indices")
    parser.add_argument(
        "--boot-delay-s",
        type=float,
        default=None,
        help="seconds from power-on or reset to the firmware's start (default 0.5; a real "
        "firmware's emulator: its board's own bootloader time)",
    )
    parser.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="K:KIND",
        help=f"fault KIND at the K-th command; kinds: {', '.join(k.value for k in FaultKind)}",
    )
    parser.add_argument("--seconds", type=float, default=None, help="stop after this long")
    args = parser.parse_args(argv)
    faults = []
    kinds = ", ".join(k.value for k in FaultKind)
    for spec in args.fault:
        at, _, kind = spec.partition(":")
        try:
            faults.append(Fault(int(at), FaultKind(kind)))
        except ValueError:
            parser.error(
                f"--fault {spec}: give K:KIND, K a command number (1 = the first), KIND "
                f"one of {kinds}"
            )
    if args.profile in SERIAL_FIRMWARES:
        given = ["--leds"] if args.leds is not None else []
        given += ["--dead"] if args.dead else []
        if given:
            parser.error(
                f"{', '.join(given)}: the {args.profile} firmware's emulator has the firmware's "
                "own LEDs; these options are for default, framed and binary"
            )
        if args.boot_delay_s is not None and not 0 <= args.boot_delay_s <= 60:
            parser.error(f"--boot-delay-s {args.boot_delay_s:g}: give 0 to 60 seconds")
        from rti_rig.simulator.domes import board_for
        from rti_rig.simulator.domes.board import BOARD_FAULT_KINDS

        other = sorted({f.kind.value for f in faults} - {k.value for k in BOARD_FAULT_KINDS})
        if other:
            parser.error(
                f"--fault {', '.join(other)}: the {args.profile} firmware's emulator does not "
                f"emulate it; it emulates {', '.join(k.value for k in BOARD_FAULT_KINDS)}"
            )
        board = board_for(args.profile, faults=FaultPlan(tuple(faults)))
        if args.boot_delay_s is not None:
            board.boot_s = args.boot_delay_s  # an instance's, not the firmware class's
        # SIGTERM (what a test harness or service manager sends) ends like Ctrl-C while it
        # serves, so the pty's temporary folder is removed instead of left behind in /tmp
        with sigterm_as_ctrl_c(), serve_on_pty(board, args.profile) as link:
            print(
                f"emulated {args.profile} firmware ({board.led_count} LEDs, "
                f"{board.baudrate} baud) on {link.port}",
                flush=True,
            )
            _serve_until_stopped(link, args.seconds)
        return 0
    leds = 48 if args.leds is None else args.leds
    settings = DomeSerialSettings(port="pty", profile=args.profile)
    firmware = firmware_for(
        settings,
        led_count=leds,
        dead_leds=frozenset(args.dead),
        boot_delay_s=RESET_BOOT_S if args.boot_delay_s is None else args.boot_delay_s,
        faults=FaultPlan(tuple(faults)),
    )
    with sigterm_as_ctrl_c(), emulated_dome_on_pty(firmware) as link:
        print(f"emulated {args.profile} dome with {leds} LEDs on {link.port}", flush=True)
        _serve_until_stopped(link, args.seconds)
    return 0


def _serve_until_stopped(link: PtyLink, seconds: float | None) -> None:
    """Wait while ``link`` serves, until Ctrl-C (or SIGTERM) or ``seconds`` have passed."""
    import time

    deadline = None if seconds is None else time.monotonic() + seconds
    try:
        while link.alive and (deadline is None or time.monotonic() < deadline):
            time.sleep(0.1)
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    # Run the main of the module as imported, not of this ``__main__`` copy: the boards of
    # ``rti_rig.simulator.domes`` test a fault's kind against the imported module's FaultKind,
    # so faults built from this copy's (another class of the same name) were never applied:
    # ``--profile nichlock --fault 3:reset`` served a board that never reset.
    from rti_rig.simulator.dome_firmware import main as _imported_main

    raise SystemExit(_imported_main())
