"""The LED dome driver: one command, one acknowledged reply, nothing guessed.

The driver translates verbs into a profile's bytes over an injected transport and reports
exactly what went wrong (timeout, garbled reply, wrong echo, reboot banner, lost port, firmware
error) as a :class:`rti_rig.runtime.dome_policy.DomeLinkError`. It never retries: deciding what is
safe to resend is the rig policy's job (``rti_rig.runtime.dome_policy.DomePolicy``).

Stale input is handled here, because only the codec-aware layer can recognise it: before each
command, bytes already waiting are read and classified (a late reply to an earlier command is
dropped, a boot banner means the board reset); while waiting, replies carrying another sequence
number are dropped as late.
"""

from __future__ import annotations

import logging

from rti_rig.core.dome_link import DomeInfo, DomeLinkError, LinkFault, OffOutcome
from rti_rig.drivers.led_dome.codec_base import DomeCodec
from rti_rig.drivers.led_dome.messages import (
    ERR_LED_FAULT,
    ERR_THERMAL,
    ERROR_CODES,
    TRANSIENT_ERROR_CODES,
    Ack,
    AllOff,
    Banner,
    Command,
    DomeIdentity,
    Garbled,
    Hello,
    Light,
    LitState,
    Nak,
    Query,
    Reply,
    Shutter,
    describe,
    error_text,
)
from rti_rig.drivers.led_dome.port_opening import PortOpening
from rti_rig.drivers.led_dome.transport import Transport, TransportError

#: What to do about a definitive refusal, said with it. A dead LED stopped a session with only
#: "LED fault (open circuit ...)" and the session's "Continue with: rti-rig run --resume": a
#: resume lights the same LED again and stops on it again.
_REMEDY = {
    ERR_LED_FAULT: "; the LED or its wiring needs repair: until then a session that lights it, "
    "or its resume, stops there again",
    ERR_THERMAL: "; let the LED cool before it is lit again",
}

#: Every byte to and from the dome goes through this logger (DEBUG, hex).
traffic_log = logging.getLogger("rti_rig.dome.traffic")


class LedDomeDriver(PortOpening):
    """Implements :class:`rti_rig.core.dome_link.DomeLink` for one protocol profile."""

    def __init__(
        self,
        transport: Transport,
        codec: DomeCodec,
        *,
        device: str = "dome",
        reply_timeout_s: float = 0.5,
        ready_timeout_s: float = 3.0,
        max_level: int = 255,
        can_dim: bool | None = None,
        senses_led_current: bool = True,
    ) -> None:
        if reply_timeout_s <= 0:
            raise ValueError(f"reply_timeout_s must be > 0, got {reply_timeout_s}")
        self.transport = transport
        self.codec = codec
        self.device = f"{device} ({transport.name}, {codec.profile} profile)"
        self.reply_timeout_s = reply_timeout_s
        self.ready_timeout_s = ready_timeout_s
        self.max_level = max_level
        #: This project's protocols carry a PWM level, unless framed with send_level = false.
        #: The factory passes the settings' answer (``DomeSerialSettings.can_dim``) so the link
        #: and ``calibrate-lights`` / the config loader cannot disagree; a driver built by hand
        #: asks its codec. A link said to dim whose codec sends no level would be a lie.
        if can_dim and not codec.has_level:
            raise ValueError(f"the {codec.profile} codec sends no level: the link cannot dim")
        self.can_dim = codec.has_level if can_dim is None else can_dim
        self.has_watchdog = codec.has_watchdog
        self.echoes_light = codec.profile != "binary"
        #: Every light command is answered (an acknowledgement, or the LED's error).
        self.light_confirmed = True
        #: A dead LED is refused (error 4, LED fault: the board senses its current), unless
        #: the config says the board measures no current (``senses_led_current = false``):
        #: the protocol cannot tell, and a check had then called a dead LED "passed".
        self.senses_led_current = senses_led_current
        self._rx = bytearray()
        self._seq = 0
        self._open = False
        #: Identity from the last boot banner (``None`` if the board sent none or a bare one).
        self.banner: DomeIdentity | None = None
        #: Boot banners seen since connect (initial one included).
        self.banners_seen = 0
        self._heard = False
        self._bytes_heard = False
        self._init_opening()
        #: This project's protocols answer ``query`` with the lit LED.
        self.can_query = True
        #: The handshake answers with the firmware's identity.
        self.identifies_itself = True
        #: Every all-off is acknowledged, or fails.
        self.off_outcome = OffOutcome.ACKNOWLEDGED
        #: The handshake is answered by a board that powers up (and resets) with every LED off.
        self.hello_leaves_dark = True

    # ------------------------------------------------------------------ lifecycle

    def connect(self) -> DomeInfo:
        """Open the port, wait for the ready banner (bounded), then handshake."""
        self.reopen_port()
        self._wait_for_banner()
        try:
            return self.hello()
        except DomeLinkError as exc:
            # Some USB-serial bridges toggle DTR twice on open, so the board can reboot once
            # more right after its first banner: one more handshake, after the new banner.
            if exc.fault is not LinkFault.RESET:
                raise
            return self.hello()

    def _boot_wait_s(self) -> float:
        """How long to wait for the ready banner after the port opens (``ready_timeout_s``)."""
        return self.ready_timeout_s

    def _refused(self, exc: TransportError) -> DomeLinkError:
        """A port the system would not open."""
        return self._error(str(exc), "open port", LinkFault.DISCONNECTED, True)

    def _wait_out_boot(self) -> None:
        """The rest of the wait for the ready banner (see :meth:`PortOpening.finish_boot`)."""
        self._wait_for_banner()

    def close(self) -> None:
        self._open = False
        self._heard = False
        self._bytes_heard = False
        self._rx.clear()
        self.transport.close()

    @property
    def port_open(self) -> bool:
        """The port is open (a board that resets on open may be booting, and boot lit)."""
        return self._open

    @property
    def profile_heard(self) -> bool:
        """Since the port was last opened, the board sent what only a board of this profile
        sends: its boot banner, or a well-formed reply (a late one included). The policy resends
        a failed handshake only then: silence or bytes this codec cannot read are what a wrong
        port, baud rate or profile gives, and resending would only delay that advice."""
        return self._heard

    @property
    def bytes_heard(self) -> bool:
        """Any byte at all came from the port since it was last opened (readable or not). A
        port silent so far may hold a board whose first reply was lost (a USB-serial adapter
        dropping bytes at the open, a board without a boot banner still booting): the policy
        sends its handshake once more then (it lights nothing), where bytes no profile reads
        are already another board's answer."""
        return self._bytes_heard

    @property
    def silence_hint(self) -> str:
        """Nothing to add to a silent port's advice: a board without auto-reset sends no
        banner, so silence through the ready wait says nothing of a slow boot."""
        return ""

    @property
    def light_window_s(self) -> float | None:
        """None: an LED stays lit until told (the watchdog, where there is one, is a limit the
        host sets with each light command, not a window of the firmware's own)."""
        return None

    @property
    def firmware_name(self) -> str | None:
        """None: the firmware names itself only in its handshake (:class:`DomeInfo`)."""
        return None

    @property
    def boots_lit_firmware(self) -> str | None:
        """None: no profile of this project's own protocols is described as booting lit (the
        policy has always taken them so)."""
        return None

    # ------------------------------------------------------------------ verbs

    def hello(self) -> DomeInfo:
        echo = self._exchange(Hello()).echo
        if not isinstance(echo, DomeIdentity):
            raise self._error(
                "handshake reply carries no identity", "handshake", LinkFault.GARBLED, True
            )
        damaged = _unprintable_field(echo)
        if damaged is not None:
            raise self._error(
                f"garbled reply (the {damaged} holds a control byte): {echo!r}",
                "handshake",
                LinkFault.GARBLED,
                True,
            )
        return DomeInfo(echo.firmware_id, echo.version, echo.led_count)

    def light(self, index: int, level: int, max_on_ms: int | None = None) -> None:
        name = describe(Light(index, level))
        if not 0 <= level <= self.max_level:
            raise self._error(
                f"level {level} outside 0..{self.max_level}", name, LinkFault.REJECTED, False
            )
        if not self.codec.has_level and level != self.max_level:
            raise self._error(
                f"the {self.codec.profile} profile is configured without intensity "
                f"(send_level = false): only full intensity 1.0 is possible",
                name,
                LinkFault.REJECTED,
                False,
            )
        self._exchange(Light(index, level, max_on_ms if self.codec.has_watchdog else None))

    def all_off(self) -> None:
        self._exchange(AllOff())

    def shutter(self, pulse_ms: int) -> None:
        self._exchange(Shutter(pulse_ms))

    def query(self) -> tuple[int | None, int]:
        echo = self._exchange(Query()).echo
        if not isinstance(echo, LitState):
            raise self._error(
                "query reply carries no state", "query lit LED", LinkFault.GARBLED, True
            )
        return echo.index, echo.level

    # ------------------------------------------------------------------ exchange

    def _exchange(self, cmd: Command) -> Ack:
        name = describe(cmd)
        if not self._open:
            raise self._error("port not open (connect first)", name, LinkFault.DISCONNECTED, True)
        try:
            try:
                self._drain_stale(name)
            except DomeLinkError as exc:
                # found before this command was written (a reboot banner, stale refusal):
                # nothing of it reached the board, which the policy must not say it did
                exc.sent = False
                raise
            self._seq = self.codec.next_seq(self._seq)
            seq = self._seq
            data = self.codec.encode_command(seq, cmd)
            traffic_log.debug("%s >> %s", self.device, data.hex(" "))
            self.transport.write(data)
            return self._await_reply(seq, cmd, name)
        except TransportError as exc:
            self._open = False
            self.transport.close()
            raise self._error(f"port lost: {exc}", name, LinkFault.DISCONNECTED, True) from exc

    def _await_reply(self, seq: int, cmd: Command, name: str) -> Ack:
        clock = self.transport.clock
        deadline = clock.now() + self.reply_timeout_s
        while True:
            reply = self._next_reply(cmd)
            if reply is None:
                remaining = deadline - clock.now()
                if remaining <= 0:
                    raise self._error(
                        f"no reply within {self.reply_timeout_s:g} s (lost or late)",
                        name,
                        LinkFault.TIMEOUT,
                        True,
                    )
                self._feed(self.transport.read(remaining))
                continue
            if isinstance(reply, Banner):
                self._saw_banner(reply)
                raise self._error(
                    "the board rebooted (boot banner) before answering", name, LinkFault.RESET, True
                )
            if isinstance(reply, Garbled):
                raise self._error(
                    f"garbled reply ({reply.reason}): {reply.raw!r}", name, LinkFault.GARBLED, True
                )
            self._heard = True  # well-formed in this profile, whatever it says
            if self.codec.has_sequence and reply.seq is not None and reply.seq != seq:
                traffic_log.debug("%s: dropped a late reply to command %s", self.device, reply.seq)
                continue
            if isinstance(reply, Nak):
                if reply.code not in ERROR_CODES:
                    raise self._error(
                        f"unknown error code {reply.code}", name, LinkFault.GARBLED, True
                    )
                raise self._error(
                    f"firmware error {reply.code}: {error_text(reply.code)}"
                    + _REMEDY.get(reply.code, ""),
                    name,
                    LinkFault.REJECTED,
                    reply.code in TRANSIENT_ERROR_CODES,
                    reply.code,
                )
            self._check_echo(cmd, reply, name)
            return reply

    def _check_echo(self, cmd: Command, ack: Ack, name: str) -> None:
        echo = ack.echo
        if echo is None:
            if isinstance(cmd, Hello | Query):
                raise self._error("reply without the expected data", name, LinkFault.GARBLED, True)
            return
        ok = True
        if isinstance(cmd, Light):
            ok = isinstance(echo, Light) and (echo.index, echo.level) == (cmd.index, cmd.level)
        elif isinstance(cmd, AllOff):
            ok = isinstance(echo, AllOff)
        elif isinstance(cmd, Shutter):
            ok = isinstance(echo, Shutter) and echo.pulse_ms == cmd.pulse_ms
        elif isinstance(cmd, Hello):
            ok = isinstance(echo, DomeIdentity)
        elif isinstance(cmd, Query):
            ok = isinstance(echo, LitState)
        if not ok:
            raise self._error(
                f"the firmware acknowledged {_describe_echo(echo)} instead",
                name,
                LinkFault.MISMATCH,
                True,
            )

    def _drain_stale(self, name: str) -> None:
        """Classify whatever arrived since the last exchange; a banner means a reset."""
        self._feed(self.transport.read(0.0))
        while True:
            reply = self._next_reply(None)
            if reply is None:
                return
            if isinstance(reply, Banner):
                self._saw_banner(reply)
                self._rx.clear()
                raise self._error(
                    "the board rebooted since the last command (boot banner)",
                    name,
                    LinkFault.RESET,
                    True,
                )
            if not isinstance(reply, Garbled):
                self._heard = True  # a late reply, well-formed in this profile
            traffic_log.debug("%s: dropped stale input %r", self.device, reply)

    def _wait_for_banner(self) -> None:
        """Wait (bounded, to the deadline set when the port opened) for the ready banner;
        boards without auto-reset send none."""
        clock = self.transport.clock
        while True:
            reply = self._next_reply(None)
            if isinstance(reply, Banner):
                self._saw_banner(reply)
                self._booted = True
                return
            if reply is not None:
                traffic_log.debug("%s: ignored before the banner: %r", self.device, reply)
                continue
            remaining = self._boot_deadline - clock.now()
            if remaining <= 0:
                traffic_log.debug(
                    "%s: no ready banner within %g s; handshaking anyway",
                    self.device,
                    self.ready_timeout_s,
                )
                self._booted = True
                return
            try:
                self._feed(self.transport.read(remaining))
            except TransportError as exc:
                self._open = False
                raise self._error(
                    f"port lost: {exc}", "wait for ready banner", LinkFault.DISCONNECTED, True
                ) from exc

    # ------------------------------------------------------------------ helpers

    def _feed(self, data: bytes) -> None:
        if data:
            self._bytes_heard = True
            traffic_log.debug("%s << %s", self.device, data.hex(" "))
            self._rx.extend(data)

    def _next_reply(self, pending: Command | None) -> Reply | None:
        while self._rx:
            reply, consumed = self.codec.decode_reply(bytes(self._rx), pending)
            if consumed:
                if reply is None:  # filler the profile skips (a blank line, whitespace)
                    traffic_log.debug("%s: skipped %r", self.device, bytes(self._rx[:consumed]))
                del self._rx[:consumed]
            if reply is not None:
                return reply
            if not consumed:
                return None
        return None

    def _saw_banner(self, banner: Banner) -> None:
        self.banners_seen += 1
        self._heard = True
        if banner.identity is not None:
            self.banner = banner.identity

    def _error(
        self,
        message: str,
        command: str,
        fault: LinkFault,
        retryable: bool,
        code: int | None = None,
    ) -> DomeLinkError:
        return DomeLinkError(self.device, message, command, fault, retryable=retryable, code=code)


def _unprintable_field(identity: DomeIdentity) -> str | None:
    """The identity field (``"firmware name"`` or ``"version"``) holding a control or other
    non-printable character, if any.

    The framed profile carries no checksum (nor does the default one with ``checksum =
    false``): a byte damaged on the wire inside the firmware's name still makes a well-formed
    frame, and the handshake had been accepted with a name such as ``'RTIDOM\\x04-EMU'`` (the
    emulator's garbled reply), which the log and ``rti-rig check`` then printed as the board's
    name. No firmware names itself with control bytes, so such a reply is garbled, and resent
    like any other garbled reply. Damage that leaves printable text cannot be told from a real
    name without a checksum: that is the profile's stated weakness (docs/protocols/led-dome.md).
    """
    for name, value in (("firmware name", identity.firmware_id), ("version", identity.version)):
        if not value.isprintable():
            return name
    return None


def _describe_echo(echo: object) -> str:
    if isinstance(echo, Light | AllOff | Shutter | Hello | Query):
        return describe(echo)
    return repr(echo)
