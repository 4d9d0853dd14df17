"""The dome link: the verbs a dome driver offers the rig and the errors it reports.

It sits in the core so that both sides can speak it without knowing each other: drivers
(``rti_rig.drivers.led_dome``) implement :class:`DomeLink` and raise :class:`DomeLinkError`;
the runtime's :class:`rti_rig.runtime.dome_policy.DomePolicy` decides what a fault means for an
acquisition (retry, reconnect, stop).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from rti_rig.core.errors import DeviceError

if TYPE_CHECKING:
    from rti_rig.core.clock import Clock


class LinkFault(StrEnum):
    """What went wrong on the link, as the driver saw it."""

    TIMEOUT = "timeout"  # no reply in time (dropped or late)
    GARBLED = "garbled"  # bytes that are not a valid reply
    MISMATCH = "mismatch"  # the echo says the firmware did something else
    RESET = "reset"  # an unexpected boot banner: the board rebooted
    DISCONNECTED = "disconnected"  # the port went away (USB drop) or is not open
    REJECTED = "rejected"  # the firmware answered ERR
    #: The firmware waits for a person, not a command (a menu, a touch-screen calibration): no
    #: resend helps (each would be one more key into it), and no LED is at fault.
    WAITING = "waiting"
    #: The board printed another known firmware's boot banner: it is not the profile's board,
    #: and the profile's commands (its all-off included) would be other keys to it (the Nab
    #: sketch's ``<0>`` steps a nichlock board to its next LED), so none is sent to it. A link
    #: that can offers ``switch_off_foreign()``: that firmware's own all-off, and nothing else
    #: (the Nab sketch boots with every LED on).
    FOREIGN = "foreign"


class DomeLinkError(DeviceError):
    """A failed exchange with the dome. ``retryable``: resending the same command may succeed."""

    def __init__(
        self,
        device: str,
        message: str,
        command: str | None,
        fault: LinkFault,
        *,
        retryable: bool,
        code: int | None = None,
        port_held: bool = False,
        permission_denied: bool = False,
        sent: bool = True,
        slow_boot: bool = False,
        damaged_reply: bool = False,
    ) -> None:
        super().__init__(device, message, command)
        self.fault = fault
        self.retryable = retryable
        self.code = code
        #: The fault is a boot banner later than the profile's boot wait (a bootloader slower
        #: than the firmware's usual one), whose advice the link also keeps as
        #: ``slow_boot_advice``. A check ended by this error (or by one raised from it) says
        #: that advice as its error; one that went on says it as a line of its own. Decided by
        #: this flag, not by finding the advice's words in the error: rewording either
        #: message had changed which the report said.
        self.slow_boot = slow_boot
        #: The unmatched reply was the expected one with a single byte damaged, lost or added:
        #: the board answers in the link's profile over a line that damaged a byte (a resend
        #: survives it; the advice is the cable), not a wrong port, baud rate or profile.
        self.damaged_reply = damaged_reply
        #: The port could not be opened because another program holds its lock (another
        #: rti-rig check or run on this dome): nothing about the board is known or wrong.
        self.port_held = port_held
        #: The port is there but this user may not open it (EACCES): its error says what to
        #: do (join the device's group), and "check that the board is plugged in" beside it
        #: would send the user to a cable that is plugged in.
        self.permission_denied = permission_denied
        #: Whether the command's bytes may have been written before it failed. False when it
        #: failed before the write (a reboot banner found waiting, the port not open): an
        #: all-off that failed so was never sent, and must not be said "sent but not
        #: acknowledged" (what the lights line had said of it).
        self.sent = sent


@dataclass(frozen=True)
class DomeInfo:
    """What the handshake told about the board."""

    firmware_id: str
    version: str
    led_count: int
    #: Where ``led_count`` came from when the firmware did not report it (a firmware that
    #: answers no identity: the rig config's protocol description); None: the firmware said.
    led_count_source: str | None = None

    def led_count_said(self) -> str:
        """``the firmware reports N LEDs``, or where the count came from if not from it."""
        if self.led_count_source is None:
            return f"the firmware reports {self.led_count} LEDs"
        return f"{self.led_count_source} gives {self.led_count} LEDs (the firmware reports none)"

    def led_count_heading(self) -> str:
        """``N LEDs`` for a heading, with where the count came from when the firmware did not
        report it: a bare "nab-rti-v1, 12 LEDs" read as a count the board had established."""
        if self.led_count_source is None:
            return f"{self.led_count} LEDs"
        return (
            f"{self.led_count} LEDs per {self.led_count_source}; this firmware does not "
            "report its count"
        )


@runtime_checkable
class DomeLink(Protocol):
    """The verbs of a dome driver (one exchange each; errors are :class:`DomeLinkError`), and
    what the policy needs to know of the link to answer a stop or a fault.

    Runtime-checkable so that a test can hold every driver to it (an ``isinstance`` check sees
    a member missing, not its type)."""

    device: str
    #: The light command carries the firmware watchdog time (max on-time).
    has_watchdog: bool
    #: The light acknowledgement echoes the LED index and level that were executed.
    echoes_light: bool
    #: Highest PWM level the firmware takes.
    max_level: int
    #: The light command carries a brightness, so an LED can be dimmed (an intensity
    #: correction applied). Declared: an on/off firmware's ``max_level`` of 1 had turned every
    #: corrected level back into full light, without a word.
    can_dim: bool
    #: The firmware can say which LED is lit (``query``). Without it and without a light echo,
    #: only the images can tell a wrong LED, which a connect says.
    can_query: bool
    #: Its connect shows the board speaks this profile (a handshake that answers). Else only a
    #: reply heard since (:attr:`profile_heard`) does: a connect to a firmware that answers
    #: nothing must not be said to have reached the board.
    identifies_itself: bool
    #: What a completed all-off establishes on this firmware (acknowledged, sent with no
    #: acknowledgement to wait for, or self-timed): the lights line says exactly that.
    off_outcome: OffOutcome
    #: A completed ``hello`` establishes that the board is dark: its handshake or init got an
    #: answer that says so (the Nab sketch's init is an acknowledged all-off; this project's
    #: protocols answer the handshake of a board that powers up dark). False where ``hello``
    #: exchanges nothing (hadrian2/RTI_Dome, minirti): a board back on USB after a drop is
    #: then said off only by a later acknowledged all-off. It had been said "off again" as soon
    #: as its port reopened, beside a lights line saying the all-off was not confirmed.
    hello_leaves_dark: bool
    #: A stop came while the port was being opened by :meth:`reopen_port`, on a port whose
    #: opening may reset the board: the policy then reopens it to send the all-off, because
    #: the reset may have lit the board (the Nab sketch boots with every LED on).
    open_cut_short: bool
    #: The firmware answers a light command (an acknowledgement, or an error for an LED it
    #: could not light): else a self-test step "passes" only as "sent without error", and
    #: only a person watching the dome knows whether the LED lit. Declared, not looked up
    #: with a default: a link lacking it had had its steps reported "passed".
    light_confirmed: bool
    #: The firmware senses LED current and refuses a dead LED (the project's protocol: error
    #: 4, "LED fault"): else an acknowledged light command says only that the board took it,
    #: and a dead LED is dark with no word (the self-test must not call its step "passed").
    senses_led_current: bool

    # The stop hooks below are what the policy asks after a stop, a failed connect or a lost
    # reply. They are declared, not looked up with defaults: a link type that lacked one had
    # silently been given "nothing to do" (no reopening, no all-off after a stop). What only a
    # described firmware can do stays optional, looked up with ``getattr`` and used where
    # present: ``published_baudrate`` / ``switch_off_at_published_rate``, ``foreign_firmware``
    # / ``switch_off_foreign``, ``slow_boot_advice``.

    @property
    def clock(self) -> Clock:
        """The clock the link's reads wait on (its transport's): a real port's emulator on a
        pseudo-terminal answers in real time, which a dry run's simulated rig time must count
        (see ``DomePolicy``); the rig's own clock when the link waits on that."""
        ...

    @property
    def port_open(self) -> bool:
        """The port is open (a board that resets on open may be booting, and boot lit)."""
        ...

    @property
    def profile_heard(self) -> bool:
        """Since the port was last opened, the board sent what only a board of this profile
        sends: the policy resends a failed handshake only then (silence or unreadable bytes
        are a wrong port, baud rate or profile, and resending only delays that advice)."""
        ...

    @property
    def bytes_heard(self) -> bool:
        """Any byte at all came from the port since it was last opened: a silent port may hold
        a board whose first reply was lost (one more handshake), and "nothing has answered:
        check the port" is said only of a port that sent nothing."""
        ...

    @property
    def silence_hint(self) -> str:
        """The end of a failed connect's advice when the port stayed silent though this
        firmware prints a boot banner at every opening (a board slower to boot than the boot
        wait); "" when there is nothing to add."""
        ...

    @property
    def light_window_s(self) -> float | None:
        """How long the firmware keeps an LED lit before it switches it off by itself (a timed
        firmware), None when it stays lit until told: the lit limit is the shorter of this
        and ``max_on_s`` (a camera fired after its LED went dark took a dark image)."""
        ...

    @property
    def firmware_name(self) -> str | None:
        """The firmware's name as its protocol description gives it, for messages; None when
        the link knows it only from the handshake (:class:`DomeInfo`)."""
        ...

    @property
    def boots_lit_firmware(self) -> str | None:
        """The firmware's name when it lights every LED as its board boots (the Nab sketch),
        else None: an all-off that failed right after an opening (which resets such a board)
        then leaves a dome that may be fully lit, and the lights line must say so."""
        ...

    def reopen_port(self) -> None:
        """Open the port (closing it first) and start the boot wait without waiting it out:
        the first step of :meth:`connect`, and how the policy gets the port back for the
        all-off when a stop cut that step short (:attr:`open_cut_short`)."""
        ...

    def finish_boot(self) -> None:
        """Wait out the rest of a boot wait a stop cut short (to the same deadline), so that
        the all-off sent next reaches the firmware and not its bootloader; nothing to do when
        the wait is over or the port is not open."""
        ...

    def connect(self) -> DomeInfo:
        """Open the port, wait for the ready banner, handshake."""
        ...

    def close(self) -> None: ...

    def hello(self) -> DomeInfo: ...

    def light(self, index: int, level: int, max_on_ms: int | None) -> None: ...

    def all_off(self) -> None: ...

    def shutter(self, pulse_ms: int) -> None: ...

    def query(self) -> tuple[int | None, int]:
        """(index lit or None, level) as the firmware sees it."""
        ...


class DomeLedError(DeviceError):
    """An error about one LED (dead, thermal limit, unknown light during a capture)."""

    def __init__(self, device: str, led: int, message: str, command: str | None) -> None:
        super().__init__(device, message, command)
        self.led = led


class OffOutcome(StrEnum):
    """What is known about the dome's lights after an all-off was attempted."""

    ACKNOWLEDGED = "acknowledged"  # sent, and the firmware confirmed it
    SENT_NO_ACK = "sent-no-ack"  # sent; this firmware never acknowledges anything
    SENT_UNCONFIRMED = "sent-unconfirmed"  # sent, but the expected acknowledgement never came
    SELF_TIMED = "self-timed"  # no all-off command: the firmware switches each LED off itself
    NOT_SENT = "not-sent"  # the link did not allow it (the port went away)
    NEVER_OPENED = "never-opened"  # the port could not be opened: this run sent nothing at all


#: The end of a lights sentence that sends the user to the dome's supply.
_CUT_SUPPLY = "; switch the dome off at its power supply"


@dataclass(frozen=True)
class OffReport:
    """The honest state of the lights after the last all-off attempt (what a user is told)."""

    outcome: OffOutcome
    detail: str = ""
    #: NEVER_OPENED because another program holds the port: the lights are that program's
    #: (switching the dome off at its supply would cut a session that runs).
    port_held: bool = False
    #: The firmware that lights every LED as its board boots, when this all-off failed right
    #: after the port opened (which resets such a board): "lights may still be on" understated
    #: a dome that, if it is that board, is fully lit. None: not such a case.
    boots_lit: str | None = None
    #: The baud rate (the firmware's published one) the port was reopened at to send the
    #: all-off again, after the one at the configured rate went unanswered on a firmware that
    #: boots lit; ``outcome`` is then what that second all-off established. None: no reopening.
    reopened_at: int | None = None
    #: SELF_TIMED: how long the firmware keeps an LED lit before it goes dark by itself (the
    #: rig config's ``light_on_s``): an LED lit just before the stop stays lit up to that long,
    #: which "it switches each LED off by itself" alone left unsaid. None: not known.
    on_time_s: float | None = None
    #: How many all-offs failed (given up unanswered, not sent) before this one, since the
    #: last that went through: said of an all-off that went through, so that a teardown
    #: problem printed for a failed all-off does not read as contradicted by "lights are off".
    after_failed: int = 0

    @property
    def lights_known_off(self) -> bool:
        return self.outcome in (OffOutcome.ACKNOWLEDGED, OffOutcome.SELF_TIMED)

    def sentence(self) -> str:
        if self.reopened_at is not None:
            return self._reopened_sentence()
        said = self._sentence()
        if self.after_failed and self.outcome in (OffOutcome.ACKNOWLEDGED, OffOutcome.SENT_NO_ACK):
            n = self.after_failed
            said += (
                f" (this all-off was sent after {n} that failed)"
                if n > 1
                else (" (this all-off was sent after one that failed)")
            )
        if self.boots_lit and self.outcome in (OffOutcome.SENT_UNCONFIRMED, OffOutcome.NOT_SENT):
            said = said.removesuffix(_CUT_SUPPLY)  # said once, at the end of what follows
            said += (
                f"; the {self.boots_lit} firmware lights every LED as its board boots, and "
                "opening the port resets the board: if this is that board, every LED is on "
                "now; switch the dome off at its power supply"
            )
        return said

    def _reopened_sentence(self) -> str:
        """What two all-offs established: the one at the configured rate, unanswered, and the
        one after reopening at the firmware's published rate (which reset the board again)."""
        firmware = self.boots_lit or "profile's"
        said = (
            "all-off sent at the configured baud rate but not acknowledged; the port was then "
            f"reopened at {self.reopened_at} baud, the {firmware} firmware's published rate "
            "(which resets the board: every LED lit while it booted), and its all-off sent "
            "there"
        )
        if self.outcome is OffOutcome.ACKNOWLEDGED:
            return f"{said} was acknowledged: lights are off"
        why = f" ({self.detail})" if self.detail else ""
        return (
            f"{said} was not acknowledged either{why}: if this is a {firmware} board, every LED "
            "is on now; switch the dome off at its power supply"
        )

    def _sentence(self) -> str:
        why = f" ({self.detail})" if self.detail else ""
        return {
            OffOutcome.ACKNOWLEDGED: "all-off sent and acknowledged by the dome: lights are off",
            OffOutcome.SENT_NO_ACK: (
                f"all-off sent; this firmware never acknowledges{why}, so lights are most likely "
                "off but that is not confirmed"
            ),
            OffOutcome.SENT_UNCONFIRMED: (
                f"all-off sent but not acknowledged{why}: lights may still be on; check the dome"
            ),
            OffOutcome.SELF_TIMED: (
                f"this firmware has no all-off command{why}: it switches each LED off by itself "
                "at the end of its on-time"
                + (
                    ""
                    if self.on_time_s is None
                    else f", so the last LED lit may stay lit for up to {self.on_time_s:g} s "
                    "(its light_on_s)"
                )
            ),
            OffOutcome.NOT_SENT: (
                f"all-off could NOT be sent{why}: lights may still be on; switch the dome off at "
                "its power supply"
            ),
            OffOutcome.NEVER_OPENED: (
                f"the dome's port is held by another program{why}, so this run lit nothing "
                "and sent nothing: the lights are that program's (if it is another rti-rig "
                "check or run, it switches them off when it ends)"
                if self.port_held
                else f"the dome's port could not be opened{why}, so this run lit nothing and "
                "could not send an all-off either; if the dome is lit from an earlier run, "
                "switch it off at its power supply"
            ),
        }[self.outcome]
