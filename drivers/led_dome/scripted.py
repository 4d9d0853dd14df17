"""A dome driver run from a protocol description (:class:`ProtocolSpec`), for real firmwares.

Real dome firmwares answer no identity handshake and no OK/ERR; some never answer, some answer
free text, some block for seconds, some frame commands by silence, some only step. This driver
does what a description says and reports what it could establish:

* replies are matched against the description (a line, a pattern, a byte); text the firmware
  prints that matches ``reset_pattern`` means the board rebooted (:attr:`LinkFault.RESET`),
  ``error_pattern`` that it refused (:attr:`LinkFault.REJECTED`), anything else unmatched within
  the timeout is reported with what was heard (:attr:`LinkFault.GARBLED`) or as silence
  (:attr:`LinkFault.TIMEOUT`);
* a timed firmware (the LED goes dark by itself) is asked to light only; ``all_off`` then waits
  for the end of the on-window, and an image taken after it is refused;
* a stepping firmware is stepped to the wanted LED and the number it prints is checked, so a
  missed or double step is a :attr:`LinkFault.MISMATCH`, never a mislabelled image.

Like :class:`LedDomeDriver` it never retries: the runtime's ``DomePolicy`` decides.
"""

from __future__ import annotations

import logging
import math
import re
from typing import Any

from rti_rig.core.dome_link import DomeInfo, DomeLedError, DomeLinkError, LinkFault, OffOutcome
from rti_rig.drivers.led_dome.damaged_reply import one_byte_off
from rti_rig.drivers.led_dome.port_opening import PortOpening
from rti_rig.drivers.led_dome.protocol_spec import CommandSpec, ProtocolSpec
from rti_rig.drivers.led_dome.transport import Transport, TransportError

traffic_log = logging.getLogger("rti_rig.dome.traffic")

#: Extra seconds the host allows past the end of a timed LED's on-window.
TIMED_MARGIN_S = 0.05
#: The port's latency counted for a reply to be heard once its last byte is on the wire: a
#: USB-serial adapter hands its bytes on when its latency timer runs out, 16 ms by default on
#: the FTDI chips of many Arduino clones (an allowance: a board that is quicker loses 16 ms of
#: the longest exposure admitted, one that is slower is caught by the all-off's own check).
REPLY_LATENCY_S = 0.016


def timed_reply_s(spec: ProtocolSpec) -> float:
    """How long after a timed LED lights its light command's reply is all heard, the host's
    capture beginning only then: the longest reply over the LEDs wired, on the wire at the
    profile's baud rate, plus :data:`REPLY_LATENCY_S`; 0 for a firmware that is not timed.

    Why: RTIPy's sketch (BeebBenjamin/RTIPy, ``arduino/rti_py/rti_py.ino``) prints ``I
    received: <command> the instructionByte was: T`` and then lights the LED and blocks for
    ``secs``, so the LED lights as the reply starts out of the board's transmit buffer (the
    driver counts the window from there, :meth:`ScriptedDomeDriver.light`). The load-time
    check of the exposure against the window (:func:`rti_rig.app.config.timed_exposure_limit`)
    had counted the capture from the LED lighting, not from the reply's end, about 50 ms (46
    characters at 9600 baud) plus the port's latency later: an exposure it admitted, at its
    "at most" figure, had every capture refused by the all-off ("went dark by itself")."""
    reply = spec.light.reply if spec.window_s is not None else None
    if reply is None or reply.kind == "none":
        return 0.0
    if reply.kind == "byte":
        chars = 1
    elif reply.pattern is None:
        return REPLY_LATENCY_S
    else:
        chars = max(
            len(
                re.sub(
                    r"\\(.)", r"\1", reply.pattern.format(**spec.values(i, frozenset()), mask="")
                )
            )
            for i in range(spec.led_count)
        )
    return chars * 10.0 / spec.baudrate + REPLY_LATENCY_S


#: Characters of the text heard since the port opened that are kept to look for a banner in
#: (the longest built-in banner, nichlock's, is under 1 kB).
HEARD_KEPT = 4096


class ScriptedDomeDriver(PortOpening):
    """Implements :class:`rti_rig.core.dome_link.DomeLink` from a :class:`ProtocolSpec`."""

    def __init__(
        self,
        transport: Transport,
        spec: ProtocolSpec,
        *,
        device: str = "dome",
        min_reply_timeout_s: float = 0.0,
        led_count_source: str | None = None,
        can_dim: bool = False,
    ) -> None:
        self.transport = transport
        self.spec = spec
        #: Where ``spec.led_count`` came from (the rig config's key, the LED map, the profile's
        #: default): the firmware never says, so a check names this instead.
        self.led_count_source = (
            led_count_source or f"the {spec.name} protocol description (led_count)"
        )
        self._device_name = device
        #: Floor under every reply timeout (``reply_timeout_s`` of the serial settings).
        self.min_reply_timeout_s = min_reply_timeout_s
        self.device = f"{device} ({transport.name}, {spec.name} profile)"
        self.has_watchdog = False
        self.max_level = 1  # on/off only
        #: A protocol description has no brightness placeholder: its light command switches an
        #: LED on (``dome_profiles.no_dimming`` says so of each built-in firmware). The factory
        #: passes the settings' answer (``DomeSerialSettings.can_dim``), the one source; the
        #: driver's own bytes are on/off, so a "yes" is refused rather than believed.
        if can_dim:
            raise ValueError(f"the {spec.name} protocol description has no level: it cannot dim")
        self.can_dim = False
        pat = spec.light.reply.pattern or ""
        self.echoes_light = spec.light.reply.kind == "pattern" and (
            "{index}" in pat or ("{row}" in pat and "{col}" in pat)
        )
        #: The firmware can say which LED is lit (none of the described firmwares can).
        self.can_query = False
        #: Its connect shows the board speaks this profile (a handshake): else the first reply
        #: will, or — for a firmware that answers nothing — nothing ever does.
        self.identifies_itself = spec.handshake is not None
        #: A light command is answered: else the self-test can only send it (whether the LED
        #: lit is seen only on the dome).
        self.light_confirmed = spec.light.reply.kind != "none"
        #: No described firmware senses LED current: its reply says the command was taken,
        #: never that the LED lit (a dead one is acknowledged all the same).
        self.senses_led_current = False
        #: What an all-off establishes on this firmware.
        self.off_outcome = (
            OffOutcome.SELF_TIMED
            if spec.all_off is None
            else OffOutcome.SENT_NO_ACK
            if spec.all_off.reply.kind == "none"
            else OffOutcome.ACKNOWLEDGED
        )
        #: ``hello`` sends an all-off and waits for the board's answer to it (the Nab sketch's
        #: init): only then is a board it reached known dark; a firmware without one, or that
        #: never answers, exchanges nothing that says so. The init command's own reply is the
        #: one ``hello`` waits for: an init described with none, beside an acknowledged
        #: ``all_off`` of the same bytes, had been taken as answered.
        off = spec.all_off
        self.hello_leaves_dark = off is not None and any(
            cmd.send == off.send and cmd.reply.kind != "none" for cmd in spec.init
        )
        self._rx = bytearray()
        self._open = False
        self._last_end = -1e9
        #: When the last command's first byte was written, and its length (a timed LED's
        #: window is counted from them).
        self._written_at = -1e9
        self._written_n = 0
        #: A byte acknowledgement is owed: the last command's timed out, and the board may
        #: still send it until this time (None: none owed). See :meth:`_wait_owed_ack`.
        self._ack_owed_until: float | None = None
        self._lit: frozenset[int] = frozenset()
        self._window_end: float | None = None
        self._timed_led: int | None = None
        self._position: int | None = 0  # stepping: the LED the next step lights (None: unknown)
        #: Text heard while waiting after opening (boot banner), for the probe and messages.
        self.boot_text = ""
        self.banners_seen = 0
        self._heard = False
        self._bytes_heard = False
        #: The text heard since the port opened (its last :data:`HEARD_KEPT` characters), where
        #: another firmware's banner is looked for: a byte-acknowledged profile reads a banner
        #: one byte at a time, and a stale one is dropped before each command.
        self._heard_text = ""
        self._init_opening()
        #: the wait after opening heard something (a banner, bootloader noise): a banner later
        #: than that is a reboot, not a late first boot
        self._boot_heard = False
        #: The built-in firmware whose boot banner the board printed, when it is not this
        #: profile's (:attr:`LinkFault.FOREIGN`): only its own all-off is sent to it from then
        #: on (:meth:`switch_off_foreign`), none of this profile's commands. None: none seen.
        self.foreign_firmware: str | None = None
        #: What that firmware's all-off established once it went through (nothing is sent to
        #: the board after it, so it holds until the port is opened again).
        self._foreign_off: OffOutcome | None = None
        self._foreign_cache: list[tuple[str, str]] | None = None
        #: What a boot banner later than the profile's boot wait said (a slow bootloader, and
        #: the ``boot_wait_s`` to set), kept for the report the user reads: as a warning on
        #: stderr alone it was missed beside ``check``'s "RESULT: PASS". None: none so far.
        self.slow_boot_advice: str | None = None

    # ------------------------------------------------------------------ lifecycle

    def connect(self) -> DomeInfo:
        self.reopen_port()
        self._wait_boot()
        self._boot_waited()
        self._refuse_foreign_banner()
        return self.hello()

    def _refuse_foreign_banner(self) -> None:
        """Refuse, before sending a byte, a board whose boot text is another built-in
        firmware's banner (and not this profile's ready text).

        Why: the profile's commands are other keys to that firmware. The nab-rti-v1 profile on a
        nichlock board sent ``<0>``, whose ``0`` stepped the board to LED 0, then the all-off
        after the failed connect stepped it to LED 1, and the user was told to check the port,
        the baud rate and the profile of a board that had printed its name."""
        name = self._foreign_banner(self.boot_text)
        if name is None:
            return
        self.foreign_firmware = name
        raise self._error(
            f"the board on this port printed the boot banner of the {name} firmware, not the "
            f"{self.spec.name} one, so none of this profile's commands was sent to it (they are "
            f"other keys to that firmware, which may light its LEDs); only that firmware's own "
            f"all-off is sent, to switch off what it lit (the lights line says what it "
            f'established): set profile = "{name}" in [dome.serial] (rti-rig probe PORT '
            "confirms it)",
            "wait after opening",
            LinkFault.FOREIGN,
        )

    def _foreign_banner(self, text: str) -> str | None:
        """The built-in firmware other than this profile's whose boot banner ``text`` holds,
        or None. Only a built-in profile's board is judged so: a custom description may be of a
        modified sketch that keeps another firmware's banner."""
        if self._heard or not text:
            return None
        for name, pattern in self._foreign_patterns():
            if re.search(pattern, text):
                return name
        return None

    def _foreign_patterns(self) -> list[tuple[str, str]]:
        """(firmware, banner pattern) of each other built-in firmware (none for a description
        that is not a built-in profile), read once: they are looked for in every reply."""
        if self._foreign_cache is None:
            from rti_rig.drivers.led_dome.dome_profiles import builtin_spec, described_profiles

            self._foreign_cache = []
            if self.spec.name in described_profiles():
                own = {self.spec.reset_pattern, self.spec.ready_pattern}
                for name in described_profiles():
                    if name == self.spec.name:
                        continue
                    other = builtin_spec(name)
                    for key in ("reset_pattern", "ready_pattern"):
                        pattern = other.get(key)
                        if pattern and pattern not in own:
                            self._foreign_cache.append((str(name), str(pattern)))
        return self._foreign_cache

    def switch_off_foreign(self) -> OffOutcome:
        """Send the all-off of the built-in firmware whose banner the board printed
        (:attr:`foreign_firmware`), and nothing else; wait for its acknowledgement where that
        firmware gives one. Returns what it established; a :class:`DomeLinkError` (naming that
        firmware) if it could not be sent or was not acknowledged.

        Why: the Nab sketch boots with every LED on. A board refused for its banner was left
        lit, told to be switched off at its supply, when its own all-off (``<0>``), which the
        board had just announced it understands, switches it off and says so. Its banner came
        through at this port's baud rate, so its all-off is sent at that rate too."""
        from rti_rig.drivers.led_dome.dome_profiles import builtin_spec
        from rti_rig.drivers.led_dome.protocol_spec import ProtocolSpec

        name = self.foreign_firmware
        if name is None:
            raise self._error(
                "no other firmware's banner was heard on this port", "all off", LinkFault.REJECTED
            )
        if self._foreign_off is not None:
            return self._foreign_off  # nothing was sent to the board since: it still holds
        theirs = ScriptedDomeDriver(
            self.transport,
            ProtocolSpec.model_validate(builtin_spec(name)),
            device=self._device_name,
            min_reply_timeout_s=self.min_reply_timeout_s,
        )
        if not self._open:
            raise theirs._error("port not open", "all off", LinkFault.DISCONNECTED)
        theirs._open = theirs._booted = True
        try:
            self._switch_off_as(theirs)
        finally:
            self._open = theirs._open
        self._foreign_off = theirs.off_outcome
        return self._foreign_off

    def _switch_off_as(self, theirs: ScriptedDomeDriver) -> None:
        """``theirs.all_off()`` once the banner ``theirs`` firmware is printing has ended."""
        # the rest of its banner first (up to its ready text): what is sent before is lost
        # while it still prints, and its banner would read as a reboot to its all-off
        self._rx.clear()
        theirs._heard_text = self._heard_text
        ready = theirs.spec.ready_pattern
        if ready and not re.search(ready, self._heard_text):
            theirs._wait_ready(
                self.transport.clock.now() + theirs.spec.boot_wait_s, self._heard_text
            )
        theirs._rx.clear()
        theirs.all_off()

    @property
    def published_baudrate(self) -> int | None:
        """The baud rate this built-in profile's firmware talks at as published, when the port
        is set to another (a ``baudrate`` left from the example config); None when it is not,
        when the description is not a built-in profile, or the transport has no baud rate (an
        in-process emulator)."""
        from rti_rig.drivers.led_dome.dome_profiles import (
            any_baudrate,
            builtin_spec,
            described_profiles,
        )

        name = self.spec.name
        port_rate = getattr(self.transport, "baudrate", None)
        if name not in described_profiles() or any_baudrate(name) or port_rate is None:
            return None
        own = int(builtin_spec(name)["baudrate"])
        return None if own == int(port_rate) else own

    def switch_off_at_published_rate(self) -> OffOutcome:
        """Reopen the port at :attr:`published_baudrate`, wait for the board to boot and send
        this profile's all-off there; the port is closed again and set back to its rate.
        Returns what the all-off established; a :class:`DomeLinkError` if it was not
        acknowledged (or the port could not be reopened).

        Why: the Nab sketch lights every LED in ``setup()``, and its Uno-class board resets when
        the port opens. At a wrong baud rate the all-off after the failed connect is garbage to
        it, and the board was left lit whole. Reopening resets it once more (lit for its boot),
        and its all-off at the rate its firmware is published with then switches it off, and is
        acknowledged, if the board is that firmware's at that rate."""
        rate = self.published_baudrate
        if rate is None:
            raise self._error(
                "the port is already at this firmware's published baud rate",
                "all off",
                LinkFault.REJECTED,
            )
        transport: Any = self.transport
        spec, port_rate = self.spec, transport.baudrate
        self.close()
        transport.baudrate = rate
        self.spec = spec.model_copy(update={"baudrate": rate})
        try:
            self.connect()  # the boot wait, then the init (the Nab sketch's is its all-off)
            self.all_off()
        finally:
            self.close()
            transport.baudrate = port_rate
            self.spec = spec
        return self.off_outcome

    def _forget_board(self) -> None:
        """At each opening: the boot wait has heard nothing yet, and no other firmware's banner
        (nor its all-off) holds for the board the opening may have reset."""
        self._boot_heard = False
        self.foreign_firmware = None
        self._foreign_off = None

    def _boot_wait_s(self) -> float:
        """The profile's boot wait (``boot_wait_s``)."""
        return float(self.spec.boot_wait_s)

    def _refused(self, exc: TransportError) -> DomeLinkError:
        """A port the system would not open."""
        return self._error(str(exc), "open port", LinkFault.DISCONNECTED)

    def _wait_out_boot(self) -> None:
        """The rest of the wait after opening (see :meth:`PortOpening.finish_boot`): straight
        to :meth:`_wait_ready`, not through :meth:`_wait_boot`, which is ``connect``'s own."""
        self._wait_ready(self._boot_deadline, "")
        self._boot_waited()

    def _boot_waited(self) -> None:
        """The wait after opening is over: whether it heard something (a banner later than
        that is a reboot, not a late first boot)."""
        self._booted = True
        self._boot_heard = bool(self.boot_text.strip())

    def close(self) -> None:
        self._open = False
        self._ack_owed_until = None  # an opening resets the board: nothing it owed will come
        self._heard = False
        self._bytes_heard = False
        self._heard_text = ""
        self._rx.clear()
        self.transport.close()

    @property
    def port_open(self) -> bool:
        """The port is open (a board that resets on open may be booting, and boot lit)."""
        return self._open

    @property
    def firmware_name(self) -> str:
        """The description's firmware name (for messages: the timed window's firmware)."""
        return self.spec.name

    @property
    def boots_lit_firmware(self) -> str | None:
        """The firmware's name when its board lights every LED as it boots (the description's
        ``boots_lit``: the Nab sketch), else None."""
        return self.spec.name if self.spec.boots_lit else None

    @property
    def light_window_s(self) -> float | None:
        """How long a lit LED stays lit before the firmware switches it off by itself (a
        timed firmware's window, RTIPy's ``T,x,y,secs``), None when it stays lit until told.

        The policy's lit limit is the shorter of this and ``max_on_s``: a busy camera awaited
        up to ``max_on_s`` under RTIPy had fired after its LED had gone dark by itself."""
        window = self.spec.window_s
        return None if window is None else float(window)

    @property
    def profile_heard(self) -> bool:
        """Since the port was last opened, the board printed what only this firmware prints:
        its ready text, its reboot text, or a reply matching the description. The policy resends
        a failed handshake or init command only then: silence or unmatched text are what a
        wrong port, baud rate or profile gives, and resending would only delay that advice
        (and send more bytes to a board of another firmware)."""
        return self._heard

    @property
    def bytes_heard(self) -> bool:
        """Any byte at all came from the port since it was last opened, as
        :attr:`~rti_rig.drivers.led_dome.driver.LedDomeDriver.bytes_heard` (why the policy asks)."""
        return self._bytes_heard

    @property
    def silence_hint(self) -> str:
        """The end of a failed connect's advice when the port sent no byte since it opened but
        this profile's board prints a boot banner at every opening: a board slower to boot than
        the boot wait (an older bootloader) stays silent through it, then prints its banner
        (and the Nab sketch lights every LED) after the connect gave up. "" otherwise."""
        spec = self.spec
        if self._bytes_heard or spec.ready_pattern is None or spec.reset_pattern is None:
            return ""
        return (
            f"; the {spec.name} board prints a boot banner each time its port opens, and none "
            f"came within the profile's boot wait (boot_wait_s = {spec.boot_wait_s:g} s): if "
            "the board is slow to boot, raise boot_wait_s in [dome.serial.protocol]"
        )

    def hello(self) -> DomeInfo:
        """Handshake (if the firmware has one) and the init commands; the board's state is
        unknown afterwards (a reboot may have lit it), so nothing is assumed lit or dark."""
        if self.spec.handshake is not None:
            self._exchange(self.spec.handshake, None, "handshake")
        for i, cmd in enumerate(self.spec.init):
            self._exchange(cmd, None, f"init command {i + 1}")
        self._position = 0
        self._lit = frozenset()
        # none of these firmwares says how many LEDs it has: the count is the description's
        return DomeInfo(
            self.spec.name,
            "",
            self.spec.led_count,
            led_count_source=self.led_count_source,
        )

    # ------------------------------------------------------------------ verbs

    def light(self, index: int, level: int = 1, max_on_ms: int | None = None) -> None:
        name = f"light LED {index}"
        if not 0 <= index < self.spec.led_count:
            raise self._error(
                f"LED {index} outside 0..{self.spec.led_count - 1}", name, LinkFault.REJECTED
            )
        if self.spec.stepping:
            self._step_to(index, name)
            return
        self._wait_window(name)
        self._exchange(self.spec.light, index, name, lit=frozenset({index}))
        self._lit = frozenset({index})
        secs = self.spec.window_s
        if secs is not None:
            # The window is counted from the earliest moment the LED can have lit: the end of
            # the command on the wire plus the silence that frames it (RTIPy's readString
            # returns 1 s after the last byte, prints its reply, and lights the LED as the
            # reply starts out of its 64-byte buffer). Counted from the reply's arrival, the
            # end had been placed one reply on the wire (about 50 ms at 9600 baud) and the
            # port's latency after the LED went dark: a capture ending in that gap was taken
            # as lit.
            start = self._written_at + self._wire_s(self._written_n) + self.spec.frame_silence_s
            self._window_end = start + secs
            self._timed_led = index

    def all_off(self) -> None:
        if self.spec.all_off is None:
            self._wait_window("all off")
            self._lit = frozenset()
            return
        self._position = None  # unknown until the all-off is confirmed
        self._exchange(self.spec.all_off, None, "all off", lit=frozenset())
        self._lit = frozenset()
        self._position = 0

    def shutter(self, pulse_ms: int = 50) -> None:
        if self.spec.shutter is None:
            raise self._error(
                "this firmware has no shutter command; let the camera trigger itself",
                "shutter",
                LinkFault.REJECTED,
            )
        self._exchange(self.spec.shutter, None, "shutter", lit=self._lit)

    def query(self) -> tuple[int | None, int]:
        raise self._error(
            "this firmware cannot say which LED is lit", "query lit LED", LinkFault.REJECTED
        )

    # ------------------------------------------------------------------ stepping / timing

    def _step_to(self, index: int, name: str) -> None:
        try:
            if self._position is None or index < self._position or self._lit:
                self.all_off()  # rewinds to the first LED (and switches the lit one off)
            assert self._position is not None
            while self._position <= index:
                target = self._position
                self._exchange(self.spec.light, target, f"{name} (step to LED {target})")
                self._position = target + 1
        except DomeLinkError:
            self._position = None  # the firmware may or may not have stepped: rewind next time
            raise
        self._lit = frozenset({index})

    def _wait_window(self, name: str) -> None:
        """Timed firmware: wait for the lit LED's window to end (the firmware blocks till then).

        An all-off that comes after the window ended means the capture outlasted the light.
        """
        end, led = self._window_end, self._timed_led
        if end is None:
            return
        clock = self.transport.clock
        now = clock.now()
        self._window_end = self._timed_led = None
        if name == "all off" and led is not None and now > end + TIMED_MARGIN_S:
            raise DomeLedError(
                self.device,
                led,
                f"LED {led} went dark by itself {now - end:.2f} s before the capture ended (its "
                f"on-time is {self.spec.light_on_s:g} s): the image may be dark; raise "
                "light_on_s in [dome.serial.protocol] or shorten settle and exposure",
                name,
            )
        if end + TIMED_MARGIN_S > now:
            clock.sleep(end + TIMED_MARGIN_S - now)

    # ------------------------------------------------------------------ exchange

    def _exchange(
        self,
        cmd: CommandSpec,
        index: int | None,
        name: str,
        *,
        lit: frozenset[int] = frozenset(),
    ) -> str:
        if not self._open:
            raise self._error("port not open (connect first)", name, LinkFault.DISCONNECTED)
        if self.foreign_firmware is not None:
            raise self._error(
                f"the board on this port runs the {self.foreign_firmware} firmware (it printed "
                f"its boot banner), so none of this profile's commands is sent to it: set "
                f'profile = "{self.foreign_firmware}" in [dome.serial]',
                name,
                LinkFault.FOREIGN,
            )
        clock = self.transport.clock
        try:
            try:
                self._wait_owed_ack()
                self._drain_stale(name)
            except DomeLinkError as exc:
                # found before this command was written (a reboot banner, stale refusal):
                # nothing of it reached the board, which the policy must not say it did
                exc.sent = False
                raise
            gap = self._last_end + max(self.spec.min_gap_s, self.spec.frame_silence_s)
            if gap > clock.now():
                clock.sleep(gap - clock.now())
            data = self.spec.render(cmd.send, index, lit)
            traffic_log.debug("%s >> %s", self.device, data.hex(" "))
            self._written_at, self._written_n = clock.now(), len(data)
            self.transport.write(data)
            sent_at = clock.now()
            heard = self._await(cmd, index, name, sent_at, len(data))
            if cmd.delay_after_s:
                clock.sleep(cmd.delay_after_s)
            self._last_end = clock.now()
            return heard
        except TransportError as exc:
            self._open = False
            self.transport.close()
            raise self._error(f"port lost: {exc}", name, LinkFault.DISCONNECTED) from exc

    def _wire_s(self, n: int) -> float:
        return n * 10.0 / self.spec.baudrate

    def _await(self, cmd: CommandSpec, index: int | None, name: str, sent: float, n: int) -> str:
        reply = cmd.reply
        if reply.kind == "none":
            # No answer ever comes: the least the command takes is its bytes' time on the wire.
            self.transport.clock.sleep(self._wire_s(n))
            return ""
        clock = self.transport.clock
        timeout = max(reply.timeout_s, self.min_reply_timeout_s)
        deadline = sent + self._wire_s(n) + self.spec.frame_silence_s + timeout
        wanted = self.spec.reply_regex(reply.pattern, index) if reply.kind == "pattern" else None
        step = self.spec.step_regex(reply.pattern) if self.spec.stepping and reply.pattern else None
        while True:
            text = self._rx.decode("latin-1")
            self._check_reset_or_error(text, name)
            if reply.kind == "byte" and self._rx:
                got = self._rx[0]
                del self._rx[:1]
                if got == reply.byte:
                    self._heard = True
                    return ""
                raise self._error(
                    f"expected acknowledgement byte 0x{reply.byte:02x}, got 0x{got:02x}",
                    name,
                    LinkFault.GARBLED,
                )
            if reply.kind == "line":
                cut = text.find("\n")
                if cut >= 0:
                    del self._rx[: cut + 1]
                    return text[: cut + 1]
            if wanted is not None:
                m = wanted.search(text)
                if m:
                    del self._rx[: len(text[: m.end()].encode("latin-1"))]
                    self._heard = True
                    return m.group(0)
                if step is not None and (s := step.search(text)) is not None:
                    del self._rx[: len(text[: s.end()].encode("latin-1"))]
                    self._heard = True
                    raise self._error(
                        f"the firmware stepped to LED {int(s.group(1)) - self.spec.index_base}, "
                        f"not LED {index} (a missed or double step)",
                        name,
                        LinkFault.MISMATCH,
                    )
            remaining = deadline - clock.now()
            if remaining <= 0 and reply.kind == "byte" and not self._rx:
                # the board may have taken the command and acknowledge it late: that byte must
                # not be read as the next command's acknowledgement
                self._ack_owed_until = clock.now() + timeout
            if remaining <= 0:
                if text.strip() and self._banner_may_be_coming():
                    # unmatched text from a board silent through its boot wait, on a profile
                    # whose board prints a banner: read on to its end (up to a boot wait) to
                    # tell a late banner (above) from a reply this profile cannot read
                    self._rx.clear()
                    self._wait_ready(clock.now() + self.spec.boot_wait_s, text)
                    ready_seen, self._heard = self._heard, False  # the banner's first sight
                    try:
                        self._check_reset_or_error(self.boot_text, name)
                    finally:
                        self._boot_heard = True  # once only: what follows is judged as replies
                    self._heard = ready_seen
                    text = self.boot_text
                if text.strip():
                    self._rx.clear()
                    damaged = wanted is not None and one_byte_off(wanted, text)
                    raise self._error(
                        f"unexpected reply {text[-120:]!r} within {deadline - sent:.2f} s"
                        + (" (the expected reply with one byte damaged)" if damaged else ""),
                        name,
                        LinkFault.GARBLED,
                        damaged_reply=damaged,
                    )
                raise self._error(
                    f"no reply within {deadline - sent:.2f} s (lost or late)",
                    name,
                    LinkFault.TIMEOUT,
                )
            self._feed(self.transport.read(remaining))

    def _check_reset_or_error(self, text: str, name: str) -> None:
        spec = self.spec
        other = self._foreign_banner(self._heard_text)
        if other is not None:
            # a banner later than the boot wait (a slow bootloader, or a profile without one:
            # rti-dome-m waits for none) had been dropped as stale input, or read a byte at a
            # time as replies: a Nab board, lit from its boot, was then said "most likely off"
            self.foreign_firmware = other
            self._rx.clear()
            after = self.transport.clock.now() - self._opened_at
            raise self._error(
                f"the board on this port printed the boot banner of the {other} firmware, not "
                f"the {spec.name} one, {after:.1f} s after the port opened (after this "
                f"profile's boot wait of {spec.boot_wait_s:g} s), so commands of this profile "
                f"had reached it before; none is sent from now on, only that firmware's own "
                f"all-off, to switch off what it lit (the lights line says what it "
                f'established): set profile = "{other}" in [dome.serial] (rti-rig probe PORT '
                "confirms it)",
                name,
                LinkFault.FOREIGN,
            )
        if spec.reset_pattern and re.search(spec.reset_pattern, text):
            # the first banner since the port opened, after a boot wait that heard nothing
            late = not self._heard and not self._boot_heard
            self.banners_seen += 1
            self._heard = True
            self._rx.clear()
            self._lit = frozenset()
            self._window_end = self._timed_led = None
            after = self.transport.clock.now() - self._opened_at
            self._wait_ready(self.transport.clock.now() + spec.boot_wait_s, text)
            if late:
                # a slow bootloader: the banner had been reported as a reboot, or (cut at a
                # reply's deadline) as an unreadable reply with "check the port, the baud
                # rate and the profile", and the Nab sketch, lit at its boot, was left lit
                self.slow_boot_advice = (
                    f"the board printed its boot banner only {after:.1f} s after the port "
                    f"opened, past this profile's boot wait (boot_wait_s = {spec.boot_wait_s:g}"
                    f" s), so what was sent before was lost: a bootloader slower than the "
                    f"{spec.name} firmware's usual one (set boot_wait_s = "
                    f"{math.ceil(after) + 1} in [dome.serial.protocol]), or a reboot"
                )
                raise self._error(self.slow_boot_advice, name, LinkFault.RESET, slow_boot=True)
            raise self._error(
                "the board rebooted (boot banner) before answering", name, LinkFault.RESET
            )
        if spec.waiting_pattern and (m := re.search(spec.waiting_pattern, text)):
            self._heard = True
            self._rx.clear()
            advice = f": {spec.waiting_advice}" if spec.waiting_advice else ""
            raise self._error(
                f"the firmware is not at its command prompt: it waits for a person "
                f"({m.group(0).strip()!r}){advice}",
                name,
                LinkFault.WAITING,
            )
        if spec.error_pattern and (m := re.search(spec.error_pattern, text)):
            self._heard = True
            self._rx.clear()
            raise self._error(f"the firmware refused: {m.group(0)!r}", name, LinkFault.REJECTED)

    def _banner_may_be_coming(self) -> bool:
        """Nothing this profile prints has been heard since the port opened, the boot wait
        heard nothing, and this profile's board prints a boot banner: text now may be a banner
        later than the boot wait (an older or slower bootloader)."""
        return (
            not self._heard
            and not self._boot_heard
            and self.spec.ready_pattern is not None
            and self.spec.reset_pattern is not None
        )

    def _wait_owed_ack(self) -> None:
        """Before a command after one whose byte acknowledgement timed out: wait, up to one
        more reply timeout, for that late byte, so the drain that follows drops it.

        Why: an acknowledgement that carries nothing but one byte (minirti's ``0x01``) cannot
        be matched to its command. Only the input already there was dropped before each
        command, so a late ``0x01`` arriving once the next command was written was counted as
        that command's own: a light the board had not acknowledged, or an all-off, was said
        acknowledged. Acknowledgements come in order, so waiting out the owed one (or the
        time it could still take) leaves the next byte to the next command. One later than
        two reply timeouts is not told apart; raise ``reply_timeout_s`` for so slow a board."""
        until, self._ack_owed_until = self._ack_owed_until, None
        if until is None:
            return
        clock = self.transport.clock
        while not self._rx and (left := until - clock.now()) > 0:
            self._feed(self.transport.read(left))
        if self._rx:
            traffic_log.debug("%s: late acknowledgement %r dropped", self.device, bytes(self._rx))

    def _drain_stale(self, name: str) -> None:
        self._feed(self.transport.read(0.0))
        if self._rx:
            text = self._rx.decode("latin-1")
            self._check_reset_or_error(text, name)
            traffic_log.debug("%s: dropped stale input %r", self.device, text)
            self._rx.clear()

    def _wait_boot(self) -> None:
        """After opening: wait for the ready text or the boot time (the board may reset)."""
        self._wait_ready(self._boot_deadline, "")

    def _wait_ready(self, deadline: float, already: str) -> None:
        clock = self.transport.clock
        heard = bytearray(already.encode("latin-1"))
        ready = re.compile(self.spec.ready_pattern) if self.spec.ready_pattern else None
        try:
            while True:
                heard += self._rx
                self._rx.clear()
                if ready is not None and ready.search(heard.decode("latin-1")):
                    self._heard = True
                    break
                remaining = deadline - clock.now()
                if remaining <= 0:
                    break
                self._feed(self.transport.read(remaining))
        except TransportError as exc:
            self._open = False
            raise self._error(
                f"port lost: {exc}", "wait after opening", LinkFault.DISCONNECTED
            ) from exc
        self.boot_text = heard.decode("latin-1")

    def _feed(self, data: bytes) -> None:
        if data:
            self._bytes_heard = True
            traffic_log.debug("%s << %s", self.device, data.hex(" "))
            self._rx.extend(data)
            self._heard_text = (self._heard_text + data.decode("latin-1"))[-HEARD_KEPT:]

    def _error(
        self,
        message: str,
        command: str,
        fault: LinkFault,
        *,
        slow_boot: bool = False,
        damaged_reply: bool = False,
    ) -> DomeLinkError:
        retryable = fault not in (LinkFault.REJECTED, LinkFault.WAITING, LinkFault.FOREIGN)
        return DomeLinkError(
            self.device,
            message,
            command,
            fault,
            retryable=retryable,
            slow_boot=slow_boot,
            damaged_reply=damaged_reply,
        )
