"""Rig-layer policy for an LED dome: what to do when the bytes go wrong, and how to spare the LEDs.

Policy above, bytes below. A dome driver (``drivers/led_dome``) only turns verbs into bytes and
reports precisely what went wrong as a :class:`DomeLinkError`. This module decides what that
means for an acquisition, and implements :class:`rti_rig.core.devices.DiscreteLightSource`:

* idempotent commands (light one LED, all off, handshake, query) are resent a bounded number of
  times after a timeout, a garbled or mismatched reply; a shutter pulse never is;
* a USB drop is answered by a bounded number of reconnections, a board reset by a new handshake;
* if the board reset or dropped while an LED was meant to be lit, the light that the last image
  was taken under is unknown: that is an error naming the LED and the command, never a silent
  recovery, so that no image is recorded under a wrong (or no) light;
* per-LED intensity correction maps a requested intensity to a PWM level;
* a thermal guard bounds each LED's continuous on-time (also sent to the firmware's watchdog when
  the profile can carry it) and its duty cycle over a sliding window, waiting on the injected
  clock for an LED to cool rather than overdriving it; its lightings outlive the command in the
  dome's duty ledger (:mod:`rti_rig.runtime.duty_ledger`: read at the first connect, written at
  close, hold and, at most every ``SAVE_EVERY_S`` of rig time, an all-off), so the next command
  on the same dome waits for the LEDs this one left hot, and says so once (a warning);
* LED index ↔ direction comes from the dome's calibrated ``.lp`` (passed in as directions).

The runtime never imports ``drivers``: the driver is reached through the core's
:class:`rti_rig.core.dome_link.DomeLink` protocol and builds its errors from
:class:`rti_rig.core.dome_link.DomeLinkError`.
"""

from __future__ import annotations

import logging
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock, VirtualClock
from rti_rig.core.deferred_signals import after_a_stop, signals_deferred
from rti_rig.core.device_said import first_clause, say_or_log
from rti_rig.core.devices import DiscreteLightSource, KnownStateLightSource
from rti_rig.core.dome_link import (
    DomeInfo,
    DomeLedError,
    DomeLink,
    DomeLinkError,
    LinkFault,
    OffOutcome,
    OffReport,
)
from rti_rig.core.errors import DeviceError
from rti_rig.core.out_folders import free_name
from rti_rig.core.rig_geometry import led_said
from rti_rig.core.shell_words import shell_word
from rti_rig.runtime.duty_ledger import SAVE_EVERY_S, DutyLedger

log = logging.getLogger("rti_rig.dome")

T = TypeVar("T")


# ----------------------------------------------------------------------------- thermal guard


@dataclass(frozen=True)
class ThermalLimits:
    """Per LED: longest continuous on-time, and highest duty over a sliding window."""

    max_on_s: float
    max_duty: float
    duty_window_s: float

    def __post_init__(self) -> None:
        if not (self.max_on_s > 0 and 0 < self.max_duty <= 1 and self.duty_window_s > 0):
            raise ValueError(f"invalid thermal limits {self}")
        if self.max_on_s > self.max_duty * self.duty_window_s:
            raise ValueError(
                f"max_on_s {self.max_on_s} s exceeds max_duty × duty_window_s "
                f"({self.max_duty * self.duty_window_s:g} s): one lighting would break the duty"
            )


class ThermalGuard:
    """On-time bookkeeping per LED, and when an LED may next be lit.

    Pure bookkeeping on times given by the caller (no clock inside), so it is tested directly.
    The start time returned by :meth:`earliest_start` assumes the next lighting lasts the full
    ``max_on_s`` (which the watchdog or the on-time check enforce), so the duty over any window
    ending at the end of that lighting stays within ``max_duty``.
    """

    def __init__(self, limits: ThermalLimits) -> None:
        self.limits = limits
        self._intervals: dict[int, list[tuple[float, float]]] = {}
        #: Lightings by an earlier command (from the duty ledger), kept apart so that a wait
        #: they cause can be said as theirs.
        self._earlier: dict[int, list[tuple[float, float]]] = {}

    def record(self, index: int, start: float, end: float) -> None:
        if end < start:
            raise ValueError(f"LED {index}: interval ends ({end}) before it starts ({start})")
        spans = self._intervals.setdefault(index, [])
        spans.append((start, end))
        horizon = end - 2 * self.limits.duty_window_s
        while spans and spans[0][1] < horizon:
            spans.pop(0)

    def remember(self, index: int, start: float, end: float) -> None:
        """Count a lighting an earlier command made (times on this guard's clock)."""
        if end < start:
            raise ValueError(f"LED {index}: interval ends ({end}) before it starts ({start})")
        self._earlier.setdefault(index, []).append((start, end))

    def earlier(self, index: int) -> list[tuple[float, float]]:
        """The lightings of ``index`` an earlier command made, as :meth:`remember` got them."""
        return list(self._earlier.get(index, ()))

    def spans(self) -> dict[int, list[tuple[float, float]]]:
        """Every known lighting, this command's and earlier ones', per LED (for the ledger)."""
        out: dict[int, list[tuple[float, float]]] = {}
        for table in (self._earlier, self._intervals):
            for index, spans in table.items():
                out.setdefault(index, []).extend(spans)
        return {i: sorted(v) for i, v in out.items()}

    def on_time(
        self, index: int, window_start: float, window_end: float, *, earlier: bool = True
    ) -> float:
        total = 0.0
        tables = (self._intervals, self._earlier) if earlier else (self._intervals,)
        for table in tables:
            for s, e in table.get(index, ()):
                total += max(0.0, min(e, window_end) - max(s, window_start))
        return total

    def earliest_start(self, index: int, now: float, *, earlier: bool = True) -> float:
        """Earliest time ≥ ``now`` at which ``index`` may be lit for up to ``max_on_s``
        (``earlier=False``: as if no earlier command had lit it)."""
        lim = self.limits
        budget = lim.max_duty * lim.duty_window_s - lim.max_on_s

        def fits(t: float) -> bool:
            on = self.on_time(index, t - lim.duty_window_s, t, earlier=earlier)
            return on <= budget + 1e-9

        if fits(now):
            return now
        lo, hi = now, now + lim.duty_window_s
        for _ in range(60):  # on_time falls monotonically as t moves on: bisect
            mid = (lo + hi) / 2
            if fits(mid):
                hi = mid
            else:
                lo = mid
        return hi


# ----------------------------------------------------------------------------- policy


@dataclass
class DomeStats:
    """What the policy had to do to keep the dome on track (for reports and tests)."""

    commands: int = 0
    retries: int = 0
    reconnects: int = 0
    rehandshakes: int = 0
    thermal_wait_s: float = 0.0
    #: ``"<command>: <fault>"`` for each fault met by a command (the connect's handshake
    #: included) that then got through; a command that failed in the end adds none (its resends
    #: still count in ``retries``).
    recovered: list[str] = field(default_factory=list)
    #: One record per reopening of a lost port (during which command, what was lost, how many
    #: attempts, the outcome, the last attempt's error): the detail the session's manifest
    #: keeps, while the user is told of it in one line and of its outcome in another.
    reconnections: list[dict[str, object]] = field(default_factory=list)


@dataclass(frozen=True)
class DomePolicySettings:
    """The policy knobs (the driver settings carry the same values from the rig config)."""

    retries: int = 2
    retry_backoff_s: float = 0.05
    reconnect_attempts: int = 3
    reconnect_backoff_s: float = 1.0
    thermal: ThermalLimits = ThermalLimits(max_on_s=10.0, max_duty=0.5, duty_window_s=60.0)
    intensity_correction: tuple[float, ...] | None = None
    confirm_with_query: bool = False
    expected_led_count: int | None = None
    shutter_pulse_ms: int = 50
    #: Said after "check the port, the baud rate and the protocol profile" when nothing on the
    #: port answered: what the rig config's rate is against the firmware's own, if they differ
    #: (a baudrate left from the example config, 115200, on a 9600-baud sketch).
    link_hint: str = ""


@dataclass(frozen=True)
class DutyWait:
    """How long this command's LEDs waited dark for the duty limit, and how much of it was for
    lightings an earlier command made (the duty ledger), under which limits."""

    waited_s: float
    for_earlier_s: float
    limits: ThermalLimits


@dataclass(frozen=True)
class _Lit:
    index: int
    level: int
    since: float


class DomePolicy:
    """An LED dome as a :class:`DiscreteLightSource`: retries, reconnection, thermal guard.

    ``link`` is the driver (connected by :meth:`connect`, never in ``__init__``); ``clock``
    measures on-times and paces back-offs and cool-downs; ``directions`` (N, 3) are the dome's
    calibrated LED directions in LED index order, from its ``.lp``.
    """

    def __init__(
        self,
        link: DomeLink,
        clock: Clock,
        settings: DomePolicySettings | None = None,
        *,
        directions: NDArray[np.float64] | None = None,
        name: str = "dome",
        ledger: DutyLedger | None = None,
    ) -> None:
        self.name = name
        self.link = link
        self.clock = clock
        self.settings = settings or DomePolicySettings()
        self.directions = None if directions is None else np.asarray(directions, dtype=float)
        self.guard = ThermalGuard(self.settings.thermal)
        self.stats = DomeStats()
        #: The duty ledger shared with earlier and later commands on this dome (None: this
        #: process alone counts its lightings). Read at the first :meth:`connect`.
        self.ledger = ledger
        self._ledger_read = False
        #: Wall-clock seconds (``time.time()``) at this clock's reading 0: the guard's times
        #: and the ledger's are one shift apart, fixed once (a wall clock set mid-command
        #: moves nothing).
        self._wall_offset = 0.0
        self._saved_at: float | None = None
        #: Seconds of :attr:`DomeStats.thermal_wait_s` due to an earlier command's lightings.
        self._earlier_wait_s = 0.0
        self._earlier_said = False
        self.info: DomeInfo | None = None
        self._lit: _Lit | None = None
        #: What the last all-off attempt established (None: none attempted yet).
        self.off_report: OffReport | None = None
        #: All-offs that failed (given up unanswered, or not sent) since the last one that
        #: went through: the next that does says it came after them (:meth:`_off_went_through`).
        self._failed_offs = 0
        #: The clock the link really waits on, when it is not the rig's simulated one: a real
        #: firmware's emulator on a pseudo-terminal answers (and blocks: 1.5 s per LED for
        #: rti-dome-m) in real time, which a dry run's rig time must count as the real rig
        #: would spend it. ``None`` when the link waits on the rig's own clock.
        link_clock = link.clock
        separate = link_clock is not clock
        self._link_clock: Clock | None = (
            link_clock if separate and isinstance(clock, VirtualClock) else None
        )
        #: Whether this policy ever had the port open (then something may have been sent).
        self._port_was_open = False
        #: Whether anything on this connection has shown that the board speaks the profile
        #: (a handshake, or a command that went through): until then a board that does not
        #: answer may be another board, or none, so a give-up names the port, baud and profile.
        self._answered = False
        #: Whether the board spoke the profile on a port this connect opened and then lost
        #: (see :meth:`_connect_link`): its port, baud rate and profile are then known right,
        #: whatever the reopened port gives.
        self._spoke_before_drop = False
        #: How far the last :meth:`connect` got, for a report that must not claim more (or
        #: less) than was established: ``"not opened"``, ``"opened"`` (the board said nothing
        #: this profile reads), ``"answered"`` (it spoke the profile, but the handshake failed)
        #: ``"connected"`` (handshake through, but the all-off that starts from the safe state
        #: failed) or ``"ready"`` (connected and switched off). None: no connect attempted.
        self.reached: str | None = None
        #: Whether a lit LED serves an image (a session, a preview, metering), so that an LED
        #: lost to a reboot or a USB drop is said to have spoilt "the image taken under" it and
        #: that capture is to be repeated. ``rti-rig check`` takes no image and clears it: its
        #: lost-LED message had spoken of an image under LED 1 that was never taken.
        self.lights_images = True
        #: The reconnect window (s) of the last reconnection that gave up on a port that did not
        #: come back (None: none gave up), and, once a later one (the closing all-off's) got the
        #: dome back after all, that window: the error said "did not come back" and the lights
        #: line then "acknowledged", which read as a contradiction, not as a USB link away for
        #: longer than the reconnect window.
        self._gave_up_after_s: float | None = None
        self.came_back_after_give_up: float | None = None
        #: The port was kept open, switched off, by :meth:`hold` for the next :meth:`connect`
        #: (metering, then the session), which then reuses it instead of reopening it.
        self._held = False
        #: Where a reopening of a lost port is said as it happens (the command line's console,
        #: set by :meth:`listen`); None: said nowhere but in the stats and the log.
        self._say: Callable[[str], None] | None = None
        #: Each failure to close the port, as said to the user (a close never raises it).
        self.close_errors: list[str] = []
        #: How the last :meth:`close` failed to release the port, in the words said to the user
        #: (None: it closed cleanly). Why apart from :attr:`close_errors`: that list keeps each
        #: text once, so a teardown's close failing as a reconnection's had was in no record of
        #: the teardown (the run's ``teardown_failures``), only said.
        self.close_failure: str | None = None
        #: A teardown's all-off has begun (:meth:`ending`, :meth:`close`; a :meth:`connect`
        #: clears it): a port lost now is reopened to send that all-off again, and nothing
        #: goes on after it.
        self._ending = False
        #: A reconnection during this teardown gave up on a port that did not come back: a
        #: later teardown all-off (the port close's, after the lighting's) then opens the port
        #: once more at once instead of waiting the reconnect window again. Both had waited it
        #: in full (2 × 7 s on the shipped emulated configs) for a port already found gone.
        self._teardown_gave_up = False

    def ending(self) -> None:
        """Mark what follows as a teardown (its all-off, then perhaps :meth:`close`), until the
        next :meth:`connect`.

        Why: a port lost during the teardown's all-off (the end of a run, or a Ctrl-C's) had
        been said as "…; the session goes on once it is back", of a session that was ending
        or had been stopped."""
        self._ending = True

    def listen(self, say: Callable[[str], None] | None) -> None:
        """Have each reopening of a lost port said through ``say`` as it happens: one line
        when it begins (what happened, and what follows once the dome is back), one with its
        outcome. ``None`` stops it.

        Why: the reopening had been told only as Python log records, which the command line
        (which configures no logging) printed raw on stderr in the middle of the progress
        bar, once per failed attempt, with the port's path three times over.

        Only *where* things are said changes: whether a teardown has begun (:meth:`ending`)
        is left as it is, as only :meth:`connect` ends it. Why: this had cleared it too, so a
        listener set (or removed) once the teardown had begun made a port lost in its all-off
        be said as "the session goes on once it is back", of a session that was ending."""
        self._say = say

    def _tell(self, text: str) -> None:
        """Say ``text`` through the listener, or as a warning record with none (it had been
        dropped: a reopening said to no listener reached no one)."""
        say_or_log(text, self._say, log)

    def _goes_on(self) -> str:
        if self._ending:
            return "the closing all-off is sent again once it is back"
        what = "session" if self.lights_images else "check"
        return f"the {what} goes on once it is back"

    def resends_said(self) -> str | None:
        """One line for the faults resent after (a reply lost, late or garbled) whose commands
        then went through, counted by fault; None when there were none.

        Why: each resend had been a raw log record on stderr, printed in the middle of the
        progress bar ("light LED 1 at level 1 failed (timeout, attempt 1): …"). A resend that
        went through changes nothing the user must do, but a count at the end says the link is
        not clean (a cable, a port, a board to look at). A lost port is left out: its reopening
        is said as it happens (:meth:`listen`)."""
        faults = [
            entry.rsplit(": ", 1)[-1]
            for entry in self.stats.recovered
            if not entry.endswith(f": {LinkFault.DISCONNECTED}")
        ]
        if not faults:
            return None
        counts = ", ".join(f"{faults.count(f)} {f}" for f in dict.fromkeys(faults))
        n = len(faults)
        return (
            f"The dome's commands were resent {n} time{'s' if n != 1 else ''} after a fault "
            f"({counts}); each resent command then went through."
        )

    # ------------------------------------------------------------------ lifecycle

    def connect(self) -> None:
        self._ending = False
        self._teardown_gave_up = False
        self._failed_offs = 0  # a new connection: the all-offs that failed were another's
        self._read_ledger()
        if self.settings.intensity_correction is not None and not self.link.can_dim:
            # before the port opens (the Nab sketch boots lit): every corrected level of an
            # on/off link had been lit at full light, as if no correction were given
            raise DeviceError(
                self.name,
                f"{self.link.device} cannot dim an LED, so its intensity_correction would be "
                "ignored: remove it from [dome.serial]",
                "connect",
            )
        if self._held:
            self._held = False
            if self.info is not None and self.link.port_open:
                # the port :meth:`hold` kept: reopening it would reset a board that resets on
                # open (an Uno-class board), and the Nab sketch boots with every LED lit until
                # the all-off; the all-off (recovered as any command's) confirms the board
                # is still there and off
                self._run(self.link.all_off, "all off")
                self.off_report = OffReport(
                    self.link.off_outcome, on_time_s=self.link.light_window_s
                )
                self._off_went_through()
                return
        self._spoke_before_drop = False
        self.reached = "not opened"
        try:
            info = self._connect_link()
        except DomeLinkError as exc:
            # asked before the port is closed (which forgets what the board sent); a firmware
            # that refused the handshake keeps the advice (another dialect, or the baud rate)
            answered = exc.command != "open port" and (
                self._spoke_before_drop or self._board_spoke_profile(exc)
            )
            spoke = answered and exc.fault is not LinkFault.REJECTED
            # a board that prints a banner at every opening, and none came (a slow bootloader)
            silent_boot = self.link.silence_hint
            if answered:
                self.reached = "answered"
            elif exc.command != "open port":
                self.reached = "opened"
            self._switch_off_then_close(partial(self._off_after_failed_connect, exc, answered))
            if exc.command == "open port" and exc.port_held:
                # the board is there and may be lit by the program using it: "check that the
                # board is plugged in" beside "switch it off at its power supply" had sent a
                # user to cut the power under a session that ran
                raise DeviceError(
                    self.name,
                    f"the dome's port is held by another program ({exc.message}): if another "
                    "rti-rig check or run is using this dome, let it finish or stop it with "
                    "Ctrl-C (it switches the lights off itself), then try again",
                    exc.command,
                ) from exc
            if exc.command == "open port":
                # a port this user may not open is there: its error says what to do, and "check
                # that the board is plugged in" had followed it (the arm's bus says it alone)
                advice = (
                    ""
                    if exc.permission_denied
                    else "; check that the board is plugged in and that the rig config's port "
                    "names it"
                )
                raise DeviceError(
                    self.name,
                    f"the dome's port could not be opened ({exc.message}){advice}",
                    exc.command,
                ) from exc
            if exc.fault is LinkFault.FOREIGN:
                raise DeviceError(exc.device, exc.message, exc.command) from exc
            if exc.fault is LinkFault.DISCONNECTED:
                # the port opened, then vanished: a USB event, which no port name, baud rate
                # or profile gives (that advice had sent users to a config that was right)
                raise DeviceError(
                    self.name,
                    f"the dome's port was lost during the {exc.command} ({exc.message}): the "
                    "USB link dropped; check the USB cable, the USB hub and the board's power "
                    "supply, then connect again",
                    exc.command,
                ) from exc
            if spoke:
                # its banner or a reply came through: port, baud rate and profile are right
                raise DeviceError(
                    self.name,
                    f"no handshake with the dome ({exc.message}); the board on this port "
                    "answers in the rig config's protocol profile (its boot banner or a reply "
                    "came through), but its handshake did not: check the USB cable and the "
                    "board's power supply",
                    exc.command,
                ) from exc
            raise DeviceError(
                self.name,
                f"no handshake with the dome ({exc.message}); check the port, the baud rate and "
                f"the protocol profile in the rig config, and that the board is powered"
                f"{self._link_hint()}{silent_boot}{self._reopened_hint()}",
                exc.command,
            ) from exc
        except BaseException:
            # an emergency stop (SIGTERM, a second Ctrl-C) while the board boots or answers
            # the handshake: the port is open and a board may boot lit, so the all-off is
            # sent before the stop goes on (it had been told "the dome was never reached"
            # with every LED of a board that boots lit still on)
            self._reopen_cut_short_port()  # not held: a further stop ends a reopening that hangs
            self._switch_off_then_close(self._switch_off_after_stop)
            raise
        self._port_was_open = True
        # a firmware without a handshake has shown nothing yet (its first reply will), unless
        # its boot text or an init command's reply came through: then "nothing on this port
        # has answered yet: check the port, the baud rate and the profile" is false (the Nab
        # sketch's banner and acknowledged init all-off had been followed by that advice when
        # the next all-off's reply was lost)
        answered = self.link.identifies_itself or self.link.profile_heard
        # the handshake, if any, got through; is it the rig config's dome?
        self.reached = "answered" if answered else "opened"
        problem = self._check_identity(info)
        if problem:
            self._switch_off_then_close(
                lambda: self._attempt_off("after the identity check failed")
            )
            raise DeviceError(self.name, problem, "handshake")
        self.info = info
        self._lit = None
        # "connected" only of a board that answered (a miniRTI board at a wrong baud rate
        # answers nothing, and its all-off failing is then no sign it was reached)
        self.reached = "connected" if answered else "opened"
        self._answered = answered
        log.info(
            "%s: %s %s with %d LEDs", self.name, info.firmware_id, info.version, info.led_count
        )
        if not self.link.can_query and not self.link.echoes_light:
            log.info(
                "%s: this firmware does not say which LED it lit; only the images can tell "
                "(rti-rig's wrong-light check)",
                self.name,
            )
        elif not self.link.echoes_light and not self.settings.confirm_with_query:
            # advice for the user, said once as the product speaks (a raw log record had been
            # printed on stderr by the command line, which configures no logging)
            log.info("%s: this profile's light acknowledgement names no LED", self.name)
            self._tell(
                "The dome's light acknowledgement does not say which LED was lit: set "
                "confirm_with_query = true in the rig config's [dome.serial] to have the firmware "
                "confirm every LED."
            )
        self._run(self.link.all_off, "all off")  # start from the safe state
        self._failed_offs = 0  # an all-off went through: none failed since
        if self.link.off_outcome is not OffOutcome.ACKNOWLEDGED:
            # an all-off nothing answers (RTIPy's wait for its window, Elexol's unanswered
            # bytes) shows no board: RTIPy's profile at a wrong baud rate had lost its port,
            # baud and profile advice at the first light's garbled reply
            self._answered = answered
        self.reached = "ready"

    def _off_after_failed_connect(self, exc: DomeLinkError, answered: bool) -> None:
        """The all-off after a connect that failed with ``exc`` (``answered``: the board spoke
        its profile), or what stands without one; run by :meth:`_switch_off_then_close`."""
        if exc.command == "open port" and not self._port_was_open:
            # Nothing was ever sent: say so, not "all-off failed, lights may be on".
            self.off_report = OffReport(
                OffOutcome.NEVER_OPENED, _open_failure_head(exc.message), port_held=exc.port_held
            )
        elif (
            exc.command == "open port"
            and self._lit is None
            and self.off_report is not None
            and self.off_report.lights_known_off
        ):
            # Open before (metering, then the session) and switched off with an
            # established all-off since: nothing was sent after it, so that still holds.
            pass
        elif exc.fault is LinkFault.FOREIGN:
            # another firmware's board: this profile's all-off is other keys to it, that
            # firmware's own all-off is not (a Nab board boots with every LED on)
            self._port_was_open = True
            self._switch_off_foreign("after the board was refused")
        elif _lost_after_opening(exc) and not self.link.port_open:
            # The port vanished and did not come back: no all-off can be written. Said as
            # that, once, in the lights line; a warning had reached the user besides it, with
            # the link's "port not open (connect first)" as the reason (Elexol's drop at '?')
            self._port_was_open = True
            log.debug("%s: no all-off after the failed connection: the port is gone", self.name)
            self.off_report = OffReport(
                OffOutcome.NOT_SENT, "the dome's port was lost and had not come back"
            )
        else:
            if exc.command != "open port":
                self._port_was_open = True
            # A board that answered nothing we understood may still be lit (one sketch
            # boots with every LED on): send the all-off anyway wherever the port is open.
            self._attempt_off(
                f"after the failed connection ({exc.message})",
                after_open=True,
                at_published_rate=not answered,
            )

    def _connect_link(self) -> DomeInfo:
        """Open the port and handshake (see :meth:`_open_and_handshake` for the resends); a port
        that vanishes after it opened (a USB drop during the boot wait, the handshake or an init
        command) is reopened by path, as a drop mid-session is.

        Before, such a drop failed the session at its start with "no handshake with the dome …
        check the port, the baud rate and the protocol profile": wrong advice for a port that
        was there and then was not. It is reopened only if the board spoke the profile before
        the drop (its banner, ready text or a well-formed reply): then the port is the dome's
        and a reconnection is what the session would do a minute later. A board heard from
        nothing before its port vanished is reopened too unless its firmware boots lit (the
        Nab sketch): one that browns out its USB port as it boots lit drops off at every
        opening, and each reopening would light it again, so connect says the port was lost
        at once. A board that boots dark and has no banner to be heard (the Elexol board, whose
        first byte from it is the answer to the handshake ``?``) had failed at once where
        every other firmware reconnected.

        Up to ``reconnect_attempts`` reopenings (none if it is 0), with the back-off doubling
        from ``reconnect_backoff_s`` on the link's clock; one whose port came back but whose
        handshake failed otherwise ends the attempts with that failure. ``stats.recovered``
        gets the faults this connect met only if its handshake got through in the end."""
        recovered: list[str] = []
        try:
            info = self._open_and_handshake(recovered)
        except DomeLinkError as exc:
            if not (
                _lost_after_opening(exc)
                and (self.link.profile_heard or self.link.boots_lit_firmware is None)
                and self.settings.reconnect_attempts > 0
            ):
                raise
            info = self._reopen_after_drop(exc, recovered)
        self.stats.recovered += recovered
        return info

    def _reopen_after_drop(self, drop: DomeLinkError, recovered: list[str]) -> DomeInfo:
        """Reopen the port a connect lost after the board had spoken the profile on it (see
        :meth:`_connect_link`); the info of the handshake that got through."""
        self._spoke_before_drop = self.link.profile_heard
        self.stats.retries += 1  # the handshake is sent again, on the reopened port
        recovered.append(f"{drop.command}: {drop.fault}")
        log.info(
            "%s: the port was lost during the %s (%s); reopening it",
            self.name,
            drop.command,
            drop.message,
        )
        info, last, came_back = self._reopen(
            recovered,
            end_when_back=True,
            drop=drop,
            during=f"the {drop.command}",
            goes_on=self._goes_on(),
        )
        if info is not None:
            return info
        if came_back and last is not None:
            raise DomeLinkError(  # back, but the handshake failed otherwise: say both
                last.device,
                f"{last.message} (after the port was lost during the {drop.command} and reopened)",
                last.command,
                last.fault,
                retryable=False,
                code=last.code,
            ) from last
        n = self.settings.reconnect_attempts
        raise DomeLinkError(
            drop.device,
            f"{drop.message}; it did not come back after {n} reconnection "
            f"attempt{'s' if n != 1 else ''} ({(last or drop).message})",
            drop.command,  # not "open port": the port was open and the handshake sent
            LinkFault.DISCONNECTED,
            retryable=False,
        ) from last

    def _open_and_handshake(self, recovered: list[str]) -> DomeInfo:
        """Open the port and handshake; a handshake (or init command) whose reply was lost,
        late or garbled, that arrived garbled (a resendable firmware error) or that a reboot
        cut short is sent again on the open port up to ``retries`` times, as any idempotent
        command is. It had not been: one reply lost at the start failed the session ("no
        handshake with the dome … check the port, the baud rate and the protocol profile"),
        from a board that had just sent its boot banner on that very port.

        Up to ``retries`` times only to a board that has spoken the profile since the port
        opened (see :meth:`_board_spoke_profile`): unreadable bytes are what a wrong baud rate
        or profile gives, which still fails at once with that advice (and sends no more bytes
        to a board of another protocol). A port wholly silent since it opened is sent it once
        more (:meth:`_port_silent`): a board without a boot banner whose first reply was lost
        had failed its connect there, where a wrong port now costs one more reply timeout.
        Each fault resent after is added to ``recovered``, which the caller counts only once
        the handshake got through; a lost port is raised as it is (:meth:`_connect_link`)."""
        try:
            return self._counted(self.link.connect)
        except DomeLinkError as first:
            exc = first
        attempt = 0
        while (
            exc.retryable
            and attempt < self.settings.retries
            and self.link.port_open
            and (self._board_spoke_profile(exc) or (attempt == 0 and self._port_silent(exc)))
        ):
            attempt += 1
            self.stats.retries += 1
            recovered.append(f"{exc.command}: {exc.fault}")
            log.info(  # counted at the end (:meth:`resends_said`), never printed raw
                "%s: %s failed while connecting (%s, attempt %d): %s",
                self.name,
                exc.command,
                exc.fault,
                attempt,
                exc.message,
            )
            if exc.slow_boot and self.lights_images:
                # what to change in the config, said once in words (a check's report says it
                # in its own line): it had reached the user only as that raw log record
                self._tell(
                    f"Slow boot: {exc.message}; the commands were sent again after the banner "
                    "and the session goes on, but each session on this board meets the same wait."
                )
            self._back_off(self.settings.retry_backoff_s)
            try:
                return self._counted(self.link.hello)
            except DomeLinkError as again:
                exc = again
        if attempt and exc.fault is not LinkFault.DISCONNECTED:
            raise DomeLinkError(
                exc.device,
                f"{exc.message}; gave up after {attempt + 1} attempts",
                exc.command,
                exc.fault,
                retryable=False,
                code=exc.code,
                damaged_reply=exc.damaged_reply,
            ) from exc
        raise exc

    def _port_silent(self, exc: DomeLinkError) -> bool:
        """The handshake timed out on a port that has sent no byte at all since it opened.

        That is a wrong or empty port, or a board whose first reply was lost: one without a
        boot banner (an Elexol board, a board whose auto-reset is off) behind a USB-serial
        adapter that drops bytes at the open, or still booting after the open's reset. Nothing
        tells them apart, so the handshake is sent once more (never more): it lights nothing
        (a handshake or init command is a query or an all-off, sent again after every reboot
        anyway), and a wrong port costs one more reply timeout before its advice. A board that
        sent bytes this profile cannot read is not resent to (another firmware's board)."""
        return exc.fault is LinkFault.TIMEOUT and not self.link.bytes_heard

    def _board_spoke_profile(self, exc: DomeLinkError) -> bool:
        """Whether the board on the port has shown, since it was opened, that it speaks the
        link's protocol profile: its boot banner or ready text, a well-formed reply (the link's
        ``profile_heard``), or the fault itself (a reboot banner, a firmware error reply, its
        expected reply with one byte damaged: a board without a banner, such as the Elexol
        24R1, had been told to check its port and baud rate when its first reply was)."""
        if exc.fault in (LinkFault.RESET, LinkFault.REJECTED) or exc.damaged_reply:
            return True
        return exc.fault in _NOT_ITS_BOARD and self.link.profile_heard

    def hold(self) -> None:
        """All off, and keep the port open for the next :meth:`connect` (metering, then the
        session), which reuses it; :meth:`close` releases it as ever.

        Why: ``run --auto-exposure`` closed the port after metering and opened it again for
        the session. An Uno-class board resets at every opening, and the Nab sketch boots
        with every LED lit until the all-off: one more spell of full light on the object
        (light dose matters to pigments, dyes and paper), and one more boot wait. An all-off
        that fails raises as :meth:`all_off` does, and the port is then closed."""
        try:
            self._all_off()
        except BaseException:
            self.close()
            raise
        if self.info is not None and self.link.port_open:
            self._held = True
            self._keep_ledger()
        else:
            self.close()

    def close(self) -> None:
        """All off (best effort), then release the port. Safe twice and after a failed connect."""
        self._held = False
        self._ending = True
        if self.info is not None:
            try:
                self._all_off()
            except DeviceError as exc:
                # the lights line says what the all-off established (off_report), in words
                log.info("%s: could not switch all off while closing: %s", self.name, exc)
        if self._lit is not None:
            # not known off: its lighting counts up to now at least (the next command's guard
            # then errs towards waiting)
            lit, now = self._lit, self.clock.now()
            self.guard.record(lit.index, lit.since, max(now, lit.since))
        self.info = None
        self._lit = None
        self.close_failure = self._quiet_close()
        self._keep_ledger()

    # ------------------------------------------------------------------ duty ledger

    def _read_ledger(self) -> None:
        """Count the lightings an earlier command made on this dome (once per policy)."""
        if self.ledger is None or self._ledger_read:
            return
        self._ledger_read = True
        window = self.settings.thermal.duty_window_s
        now = self.clock.now()
        self._wall_offset = self.ledger.wall() - now
        read = self.ledger.load(window)
        for index, spans in read.spans.items():
            for start, end in spans:
                self.guard.remember(index, start - self._wall_offset, end - self._wall_offset)
        self._saved_at = now

    def _keep_ledger(self, *, throttled: bool = False) -> None:
        """Write this dome's lightings of the last duty window to the ledger; ``throttled``:
        only if :data:`SAVE_EVERY_S` of the rig's clock passed since the last write (an
        all-off's, so that a session is not slowed by a write per image)."""
        if self.ledger is None or not self._ledger_read:
            return
        now = self.clock.now()
        if throttled and self._saved_at is not None and now - self._saved_at < SAVE_EVERY_S:
            return
        self._saved_at = now
        offset = self._wall_offset
        spans = {i: [(s + offset, e + offset) for s, e in v] for i, v in self.guard.spans().items()}
        self.ledger.save(spans, now + offset, self.settings.thermal.duty_window_s)

    def duty_wait(self) -> DutyWait:
        """How long this command's LEDs waited dark for the duty limit (see :class:`DutyWait`)."""
        return DutyWait(self.stats.thermal_wait_s, self._earlier_wait_s, self.settings.thermal)

    def _say_earlier_wait(self, index: int, now: float, wait_s: float) -> None:
        """Say once per command that an LED waits for what an earlier command lit."""
        if self._earlier_said:
            return
        self._earlier_said = True
        spans = self.guard.earlier(index)
        window = self.settings.thermal.duty_window_s
        lit = sum(max(0.0, e - max(s, now - window)) for s, e in spans)
        ago = max(0.0, now - max(e for _, e in spans)) if spans else 0.0
        warnings.warn(
            f"{self.led_said(index)} was lit {lit:.1f} s by an earlier command {ago:.0f} s "
            f"ago: waiting "
            f"{wait_s:.1f} s for its duty limit ([dome.serial.thermal] max_duty = "
            f"{self.settings.thermal.max_duty:g} over duty_window_s = {window:g} s)",
            RuntimeWarning,
            stacklevel=3,
        )

    def light_count(self) -> int:
        if self.info is not None:
            return self.info.led_count
        if self.directions is not None:
            return len(self.directions)
        raise DeviceError(self.name, "LED count unknown before connect(); connect first")

    def direction_of(self, index: int) -> NDArray[np.float64]:
        """Calibrated direction of LED ``index`` (from the dome's ``.lp``)."""
        if self.directions is None:
            raise DeviceError(self.name, "no calibrated LED directions were given (.lp file)")
        self._check_index(index, len(self.directions))
        return self.directions[index].copy()

    def led_said(self, index: int) -> str:
        """LED ``index`` as a user is told of it: ``LED 36 (az 112.5°, el 55.0°)``
        (:func:`rti_rig.core.rig_geometry.led_said`), the number alone only where no calibrated
        direction is known for it (no ``.lp`` given, or an index the firmware reported beyond
        the dome's). Why: "LED 36" alone sends the user counting LEDs round the dome; its
        direction says which one to look at."""
        if self.directions is not None and 0 <= index < len(self.directions):
            return led_said(index, self.directions[index])
        return f"LED {index}"

    # ------------------------------------------------------------------ verbs

    def light(self, index: int, intensity: float = 1.0) -> None:
        """Light ``index`` alone at ``intensity`` (0, 1], corrected per LED."""
        info = self._require_connected(f"light LED {index}")
        self._check_index(index, info.led_count)
        level = self.level_for(index, intensity)
        command = f"light LED {index} at level {level}"
        self._check_on_time(command)
        now = self.clock.now()
        start = self.guard.earliest_start(index, now)
        if start > now:
            log.info("%s: LED %d cools for %.3f s (duty limit)", self.name, index, start - now)
            alone = self.guard.earliest_start(index, now, earlier=False)
            if start > alone + 1e-6:  # an earlier command's lightings hold it back
                self._earlier_wait_s += start - alone
                self._say_earlier_wait(index, now, start - now)
            self.clock.sleep(start - now)
            self.stats.thermal_wait_s += start - now
        max_on_ms = math.ceil(self.settings.thermal.max_on_s * 1000)
        watchdog = max_on_ms if self.link.has_watchdog else None

        def fire() -> None:
            self.link.light(index, level, watchdog)
            if self.settings.confirm_with_query:
                lit, got = self.link.query()
                if lit != index or got != level:
                    raise DomeLinkError(
                        self.link.device,
                        f"the firmware reports {self.led_said(lit)} at level {got} lit, not "
                        f"{self.led_said(index)} at level {level}",
                        command,
                        LinkFault.MISMATCH,
                        retryable=True,
                    )

        try:
            self._run(fire, command)
        except DomeLinkError as exc:
            self._fail_safe()
            if exc.fault is LinkFault.REJECTED:
                raise DomeLedError(
                    self.name, index, f"{self.led_said(index)} refused: {exc.message}", command
                ) from exc
            raise
        since = self.clock.now()
        previous = self._lit
        if previous is not None and previous.index == index:
            since = previous.since  # lit again without a pause: the on-time keeps counting
        elif previous is not None:
            self.guard.record(previous.index, previous.since, since)
        self._lit = _Lit(index, level, since)

    def all_off(self) -> None:
        """Every LED off (the safe state); reports an LED that overran its on-time."""
        self._all_off()
        self._keep_ledger(throttled=True)

    def _all_off(self) -> None:
        """:meth:`all_off` without its throttled ledger write: :meth:`close` and :meth:`hold`
        write the ledger themselves, unthrottled, right after (it had been written twice)."""
        if self.info is None:
            return
        try:
            self._run(self.link.all_off, "all off")
        except DomeLinkError as exc:
            if self._lit is not None:  # its lighting counts, up to now at least
                self.guard.record(self._lit.index, self._lit.since, self.clock.now())
            self._lit = None
            if exc.fault is LinkFault.FOREIGN:
                self._switch_off_foreign("in place of this profile's all-off")
            else:
                self._failed_offs += 1
                self.off_report = _failed_off(exc)
            raise
        self.off_report = OffReport(self.link.off_outcome, on_time_s=self.link.light_window_s)
        self._off_went_through()
        self._check_on_time("all off")
        if self._lit is not None:
            self.guard.record(self._lit.index, self._lit.since, self.clock.now())
        self._lit = None

    def shutter(self, pulse_ms: int | None = None) -> None:
        """Pulse the camera release line. Never resent: a resend could take a second picture."""
        self._require_connected("shutter")
        ms = self.settings.shutter_pulse_ms if pulse_ms is None else int(pulse_ms)
        self._run(lambda: self.link.shutter(ms), f"shutter pulse {ms} ms", idempotent=False)

    def lit_limit_s(self) -> float:
        """How long one LED may stay lit at a time: ``max_on_s``, or the firmware's own window
        where it switches the LED off by itself sooner (RTIPy lights for ``light_on_s`` whole
        seconds). A busy camera awaited for ``max_on_s`` under RTIPy had been fired after its
        LED had gone dark by itself, and the all-off then refused the image late."""
        limit = self.settings.thermal.max_on_s
        window = self.link.light_window_s
        return limit if window is None else min(limit, float(window))

    def lit_limit_said(self) -> str:
        """What sets :meth:`lit_limit_s`, for a message: ``max_on_s = 8 s``, or the timed
        firmware's window (``the 2 s the rtipy firmware keeps it lit (light_on_s)``)."""
        limit = self.settings.thermal.max_on_s
        window = self.link.light_window_s
        if window is None or window >= limit:
            return f"max_on_s = {limit:g} s"
        firmware = self.link.firmware_name or "dome's"
        return (
            f"the {float(window):g} s the {firmware} firmware keeps it lit before switching it "
            "off by itself (light_on_s)"
        )

    def lit_state(self) -> tuple[int | None, int]:
        """What the firmware itself says is lit (index or None, level)."""
        self._require_connected("query")
        return self._run(self.link.query, "query lit LED")

    def level_for(self, index: int, intensity: float) -> int:
        """PWM level for ``intensity`` on LED ``index`` after its intensity correction. A
        refusal names the LED by its number and direction (:meth:`led_said`), as the module's
        other refusals do: "LED 2" alone sent the user counting LEDs round the dome."""
        if not (math.isfinite(intensity) and 0.0 < intensity <= 1.0):
            raise DeviceError(
                self.name,
                f"intensity {intensity} for {self.led_said(index)} is outside (0, 1]",
                f"light LED {index}",
            )
        corr = self.settings.intensity_correction
        factor = 1.0 if corr is None else corr[index]
        level = round(intensity * factor * self.link.max_level)
        if level > self.link.max_level:
            raise DomeLedError(
                self.name,
                index,
                f"{self.led_said(index)} cannot give intensity {intensity}: with its correction "
                f"{factor:g} it would need level {level} > {self.link.max_level}; lower the "
                "intensity or renormalise the correction list so its largest factor is 1",
                f"light LED {index}",
            )
        return max(level, 1)

    # ------------------------------------------------------------------ internals

    def _run(
        self,
        op: Callable[[], T],
        command: str,
        *,
        idempotent: bool = True,
    ) -> T:
        """Run one exchange with bounded retries, reconnection and the lost-light check.

        The faults resent after go to ``stats.recovered`` once the command got through, not
        as they are resent: a command that gave up after its resends had been listed as
        recovered from the very faults that stopped it."""
        attempt = 0
        resent: list[str] = []
        while True:
            self.stats.commands += 1
            try:
                result = self._counted(op)
            except DomeLinkError as exc:
                fault = exc.fault
                # never a warning the command line would print raw beside its progress bar: a
                # lost port is said as it is reopened (:meth:`_reopen`), a resend that went
                # through is counted at the end (:meth:`resends_said`), and one that gave up
                # raises the error the command says
                log.info(
                    "%s: %s failed (%s, attempt %d): %s",
                    self.name,
                    command,
                    fault,
                    attempt + 1,
                    exc.message,
                )
                if fault in (LinkFault.RESET, LinkFault.DISCONNECTED) and self._lit is not None:
                    lost = self._lit
                    self._lit = None
                    self.guard.record(lost.index, lost.since, self.clock.now())
                    # "went dark with it" was not established: a board powered apart from
                    # its USB link keeps its LED lit through a drop of the port
                    lit = f"{self.led_said(lost.index)} was meant to be lit when the port went"
                    stops = (
                        f"{lit}, so the session stops at its image"
                        if self.lights_images
                        else f"{lit}, so the check fails there"
                    )
                    back = self._recover(exc, command, goes_on=None if self._ending else stops)
                    what = "rebooted" if fault is LinkFault.RESET else "dropped off the USB bus"
                    # "off again" only once the handshake after the reboot went through: a
                    # board that rebooted again there (the Nab sketch boots lit) had been said
                    # off while every LED was on
                    # and only where that handshake says so (an acknowledged all-off): one
                    # that exchanges nothing (RTI_Dome, minirti) had the dome said "off
                    # again" with nothing sent since its port came back
                    state = (
                        "the dome is off again"
                        if back and self.link.hello_leaves_dark
                        else "whether the dome is dark is what the closing all-off "
                        "established (see the lights line)"
                        if back
                        else "its handshake after the reboot failed too, so whether the dome "
                        "is lit is unknown until the closing all-off (see the lights line)"
                    )
                    if self.lights_images:
                        lost_what = (
                            f"the image taken under LED {lost.index} may have had no light; "
                            f"{state}; repeat that capture"
                        )
                    else:
                        lost_what = (
                            # not "went dark with it": a board powered apart from its USB
                            # link stays lit, and the Nab sketch boots with every LED on
                            f"this check takes no image under LED {lost.index}, so nothing is "
                            f"lost with it; "
                            f"{state}; a board that {what} by itself points to its power "
                            "supply or its USB cable: check them, then run the check again"
                        )
                    raise DomeLedError(
                        self.name,
                        lost.index,
                        f"the board {what} while {self.led_said(lost.index)} was meant to be "
                        f"lit (found "
                        f"during '{command}'): {lost_what}",
                        command,
                    ) from exc
                if not exc.retryable or not idempotent or attempt >= self.settings.retries:
                    if not idempotent and exc.retryable:
                        why = " (not resent: it is not idempotent)"
                    elif exc.retryable:
                        why = f"; gave up after {attempt + 1} attempt{'s' if attempt else ''}"
                    else:
                        why = (
                            f" (after {attempt} resend{'s' if attempt > 1 else ''})"
                            if attempt
                            else ""
                        )
                    talked = self.link.bytes_heard
                    if not self._answered and fault is LinkFault.TIMEOUT and not talked:
                        why += (
                            "; nothing on this port has answered yet: check the port, the baud "
                            "rate and the protocol profile in the rig config, and that the "
                            f"board is powered{self._link_hint()}"
                        )
                    elif not self._answered and fault in _NOT_ITS_BOARD:
                        # bytes came back (a banner, another firmware's replies, a banner at
                        # another baud rate before a reply timed out): a board is there and
                        # talks, which "nothing has answered … and that the board is powered"
                        # had denied
                        why += (
                            "; a board on this port sends bytes, but none this rig config's "
                            "protocol profile understands: check the profile (rti-rig probe "
                            "PORT names the firmware it finds) and the baud rate"
                            + self._link_hint()
                        )
                    raise DomeLinkError(
                        self.name,
                        f"{exc.message}{why}",
                        command,
                        fault,
                        retryable=False,
                        code=exc.code,
                        sent=exc.sent,
                    ) from exc
                attempt += 1
                self.stats.retries += 1
                self._recover(exc, command)
                resent.append(f"{command}: {fault}")
            else:
                self._answered = True
                self.stats.recovered += resent
                return result

    def _recover(self, exc: DomeLinkError, command: str, goes_on: str | None = None) -> bool:
        """Bring the link back after ``exc`` so that the command can be sent again. False when
        the handshake after a reboot failed (what the board then has lit is unknown), True
        otherwise (a failed reconnection raises). ``goes_on``: what follows once the dome is
        back, as the user is told when a lost port is reopened (default: the run goes on)."""
        if exc.fault is LinkFault.DISCONNECTED:
            self._reconnect(command, exc, goes_on)
        elif exc.fault is LinkFault.RESET:
            self.stats.rehandshakes += 1
            try:
                info = self._counted(self.link.hello)
            except DomeLinkError as again:
                if again.fault is LinkFault.DISCONNECTED:
                    self._reconnect(command, again, goes_on)
                    return True
                # the resend that follows is bounded by the retry count anyway
                log.info("%s: handshake after a reset failed: %s", self.name, again)
                return False
            problem = self._check_identity(info)
            if problem:
                raise DeviceError(self.name, f"after a board reset: {problem}", command)
        else:
            self._back_off(self.settings.retry_backoff_s)
        return True

    def _back_off(self, seconds: float) -> None:
        """Wait ``seconds`` for the device: a back-off gives the board (a USB device coming back
        on the bus, a reply on its way) time on the clock the link really waits on, counted on
        the rig's. On the rig's simulated clock alone it had passed no time for an emulated
        dome on a pseudo-terminal, which runs in real time: a USB drop of a second was never
        recovered in a dry run (every reconnection tried at once, "did not come back"), where
        the real rig's back-off waits for it."""
        if seconds <= 0:
            return
        link_clock = self._link_clock
        if link_clock is None:
            self.clock.sleep(seconds)
        else:
            self._counted(lambda: link_clock.sleep(seconds))

    def _reconnect(self, command: str, drop: DomeLinkError, goes_on: str | None = None) -> None:
        """Reopen the port a session lost (``drop``, a USB drop during ``command``) and check
        it is the same dome."""
        recovered: list[str] = []
        # a teardown whose reconnection window already ran out without the port: one more
        # opening (the port may be back: its all-off is then sent), no second wait
        once = self._ending and self._teardown_gave_up
        info, last, came_back = self._reopen(
            recovered,
            end_when_back=False,
            drop=drop,
            during=f"'{command}'",
            goes_on=goes_on or self._goes_on(),
            once=once,
        )
        if info is not None:
            self._teardown_gave_up = False
            problem = self._check_identity(info)
            if problem:
                self._quiet_close()
                raise DeviceError(self.name, f"after reconnecting: {problem}", command)
            self.stats.recovered += recovered
            if self._gave_up_after_s is not None:
                self.came_back_after_give_up = self._gave_up_after_s
            return
        # "did not come back" only of a port that did not: one that reopened but whose board
        # did not answer its handshake is said so (the board, not the USB link, is in question)
        tries = self.settings.reconnect_attempts
        attempts = f"{tries} reconnection attempt{'' if tries == 1 else 's'}"
        said = last.message if last is not None else "no attempt made"
        if came_back:
            outcome = (
                f"its port came back but the board did not answer its handshake after "
                f"{attempts} ({said}); check the USB cable and the dome's power"
            )
        elif once:
            window = self.reconnect_window_s()
            outcome = (
                f"did not come back: this teardown already gave it {attempts} over "
                f"{window:.1f} s, and one more opening without waiting found it still gone "
                f"({said}); check the USB cable, the hub and the dome's power, or "
                f"{self._window_keys()}"
            )
        else:
            window = self.reconnect_window_s()
            self._gave_up_after_s = window
            self._teardown_gave_up = self._ending
            outcome = (
                f"did not come back within {attempts} over {window:.1f} s ({said}); check the "
                f"USB cable, the hub and the dome's power, or {self._window_keys()}"
            )
        raise DomeLinkError(
            self.name,
            f"the dome dropped off and {outcome}",
            command,
            LinkFault.DISCONNECTED,
            retryable=False,
        )

    def reconnect_window_s(self) -> float:
        """Seconds of back-off over which a lost port is tried again before giving up."""
        s = self.settings
        return s.reconnect_backoff_s * (2**s.reconnect_attempts - 1)

    def _window_keys(self) -> str:
        s = self.settings
        return (
            f"raise reconnect_attempts (now {s.reconnect_attempts}) or reconnect_backoff_s (now "
            f"{s.reconnect_backoff_s:g} s, doubled at each attempt) in [dome.serial] if it drops "
            "off for longer"
        )

    def _reopen(
        self,
        recovered: list[str],
        *,
        end_when_back: bool,
        drop: DomeLinkError,
        during: str,
        goes_on: str,
        once: bool = False,
    ) -> tuple[DomeInfo | None, DomeLinkError | None, bool]:
        """Close the port and open it again by path, up to ``reconnect_attempts`` times, the
        back-off doubling from ``reconnect_backoff_s`` on the link's clock; each opening
        handshakes as a connect does (:meth:`_open_and_handshake`: a lost reply is resent once
        the board has spoken the profile, its faults added to ``recovered``).

        One loop for a drop at the connect and a drop mid-session (they had been two copies,
        and the session's did not resend a lost handshake reply on the reopened port: one lost
        reply cost a whole reconnection attempt). Returns the info of the handshake that got
        through (``stats.reconnects`` counted), else None, the last failure and whether its port
        had come back. ``end_when_back``: stop at the first port that came back but whose
        handshake failed otherwise (a connect: that board's answer is then what is in
        question), rather than trying again (mid-session: a board may still be booting).

        ``drop`` (the loss that led here, ``during`` a command) is said through
        :meth:`listen`'s ``say`` as the reopening begins, with ``goes_on`` (what follows once
        the dome is back), and the outcome once it is known; each reopening is recorded in
        ``stats.reconnections``. ``once``: one opening, at once (a teardown whose window already
        ran out without the port), said as such."""
        n = 1 if once else self.settings.reconnect_attempts
        if once:
            self._tell(
                f"The dome's port is still gone at {during}: this teardown already waited "
                f"{self.reconnect_window_s():.1f} s for it, so it is opened once more without "
                f"waiting again; {goes_on}."
            )
        else:
            self._tell(
                f"The dome dropped off the USB bus during {during}: reopening its port (up to "
                f"{n} attempt{'s' if n != 1 else ''} over {self.reconnect_window_s():.1f} s); "
                f"{goes_on}."
            )
        last: DomeLinkError | None = None
        came_back = False
        tries = 0
        info: DomeInfo | None = None
        for attempt in range(n):
            tries = attempt + 1
            self._quiet_close()
            if not once:
                self._back_off(self.settings.reconnect_backoff_s * (2**attempt))
            try:
                info = self._open_and_handshake(recovered)
            except DomeLinkError as exc:
                last = exc
                came_back = not (exc.command == "open port" or _lost_after_opening(exc))
                log.info("%s: reconnection %d failed: %s", self.name, attempt + 1, exc)
                if came_back and end_when_back:
                    break
                continue
            self.stats.reconnects += 1
            break
        if info is None and not (came_back and end_when_back):
            self._quiet_close()
        attempts = f"{tries} attempt{'s' if tries != 1 else ''}"
        if info is not None:
            outcome = "reconnected"
            # "it answered" only of a board whose connect exchanged a reply: a firmware
            # without a handshake (RTI_Dome never replies) had been said to have answered
            if self.link.identifies_itself or self.link.hello_leaves_dark:
                self._tell(
                    f"The dome is back: its port reopened and it answered, after {attempts}."
                )
            else:
                self._tell(
                    f"The dome is back: its port reopened after {attempts} (this firmware has "
                    "no handshake, so nothing has answered yet)."
                )
        elif came_back:
            outcome = "port back, no handshake"
            self._tell(
                "The dome's port came back but the board did not answer its handshake, after "
                f"{attempts} (said below)."
            )
        else:
            outcome = "did not come back"
            self._tell(f"The dome's port did not come back, after {attempts} (said below).")
        self.stats.reconnections.append(
            {
                "during": during.strip("'"),
                "lost": drop.message,
                "attempts": tries,
                "outcome": outcome,
                "last_error": None if info is not None or last is None else last.message,
            }
        )
        if info is not None:
            return info, None, False
        return None, last, came_back

    def _check_identity(self, info: DomeInfo) -> str | None:
        s = self.settings
        n = info.led_count
        said = info.led_count_said()  # names where the count came from
        if n < 1:
            return said
        if self.info is not None and n != self.info.led_count:
            return f"{said}, not {self.info.led_count} as before"
        if s.expected_led_count is not None and n != s.expected_led_count:
            return f"{said} but the rig config expects {s.expected_led_count} (expected_led_count)"
        if self.directions is not None and len(self.directions) != n:
            return f"{said} but the rig config's [dome] layout gives {len(self.directions)} lights"
        if s.intensity_correction is not None and len(s.intensity_correction) != n:
            return f"intensity_correction has {len(s.intensity_correction)} factors but {said}"
        return None

    def _check_on_time(self, command: str) -> None:
        """An LED on longer than max_on_s was cut by the watchdog (or overheated): say so."""
        lit = self._lit
        if lit is None:
            return
        on_s = self.clock.now() - lit.since
        limit = self.settings.thermal.max_on_s
        if on_s > limit + 1e-9:
            self.guard.record(lit.index, lit.since, self.clock.now())
            self._lit = None
            self._fail_safe()
            cut = (
                " the firmware watchdog switched it off, so the image taken under it may be dark;"
                if self.link.has_watchdog
                else ""
            )
            raise DomeLedError(
                self.name,
                lit.index,
                f"{self.led_said(lit.index)} stayed on {on_s:.3f} s, beyond max_on_s = "
                f"{limit:g} s;{cut} "
                "raise max_on_s or shorten settle and exposure",
                command,
            )

    def _fail_safe(self) -> None:
        """Try to reach the safe state after an error, without masking that error."""
        self._attempt_off("after an error")
        self._lit = None

    def _counted(self, op: Callable[[], T]) -> T:
        """``op()``, its time on the link's real clock added to the rig's simulated clock
        (see ``_link_clock``; nothing to add when the link waits on the rig's clock)."""
        if self._link_clock is None:
            return op()
        t0 = self._link_clock.now()
        try:
            return op()
        finally:
            self.clock.sleep(max(0.0, self._link_clock.now() - t0))

    def _switch_off_then_close(self, switch_off: Callable[[], None]) -> None:
        """``switch_off()`` with further SIGINT/SIGTERM held until it is through, then the port
        closed, whatever happened.

        Why: an all-off after a connect that failed or was stopped may first reopen the port
        (at the firmware's published rate, or after a stop inside the opening), which resets a
        board that resets on open, and the Nab sketch then boots with every LED lit. A Ctrl-C
        during that boot wait (about 7 s with the Nab profile) had cut the all-off short and
        left the board, reset by our own reopen, lit whole; the signal now acts once the
        all-off is through."""
        try:
            with signals_deferred():
                switch_off()
        finally:
            self._quiet_close()

    def _switch_off_after_stop(self) -> None:
        """The all-off after a stop cut :meth:`connect` short, once the board has booted (the
        port opened again first, by :meth:`_reopen_cut_short_port`, if the stop cut its opening
        short). Run with further signals held (see :meth:`connect`): a second Ctrl-C during its
        boot wait, the usual answer to a command that does not stop at once, had cut it short
        and left the Nab board, which boots lit, with every LED on; the signal acts once the
        all-off is through."""
        if not self.link.port_open:
            return
        self._port_was_open = True
        self.reached = "opened"
        # what stands if the attempt is cut short all the same (an error that is no signal);
        # the attempt replaces it with what it established
        self.off_report = OffReport(
            OffOutcome.NOT_SENT,
            "a further stop cut the all-off short",
            boots_lit=self._lit_at_boot(),
        )
        # the stop and the lights line say this in words (the off_report set above)
        log.info("%s: stopped while connecting: switching the dome off first", self.name)
        self._finish_boot()
        self._attempt_off("after the connection was interrupted", after_open=True)

    def _reopen_cut_short_port(self) -> None:
        """Open the port again after a stop cut its opening short, so that the all-off can be
        sent (the caller sends it once the board has booted).

        Why: a Ctrl-C inside pyserial's open (which closes the port as the stop goes through)
        left a port this link never had open: no all-off was sent and the user was told "the
        dome was never reached", while the opening had reset the board, and the Nab sketch
        boots with every LED lit. Reopening resets such a board once more (lit while it
        boots), then its all-off switches it off, acknowledged where the firmware does. If the
        port does not open again, the lights line says the all-off was not sent.

        Run before the held block, with signals as they are: an opening can hang (a port that
        does not answer its open), and held signals had made a second Ctrl-C wait it out; a
        further stop now ends it at once, the port closed and the lights line saying the
        all-off was not sent. Only an opening that may reset the board (a serial device's, see
        ``SerialTransport.resets_on_open``) is reopened: the link leaves ``open_cut_short``
        false for one that resets nothing, such as a URL port's connect."""
        if not self.link.open_cut_short:
            return
        self._port_was_open = True  # the system opened it: a board that resets on open did
        self.reached = "opened"
        self.off_report = OffReport(
            OffOutcome.NOT_SENT,
            "the stop came while the port was being opened, and it was not opened again",
            boots_lit=self._lit_at_boot(),
        )
        # said in words by the lights line (the off_report set here and below)
        log.info("%s: reopening the port a stop cut short, to send the all-off", self.name)
        try:
            with after_a_stop():  # a further stop ends this reopening at once
                self._counted(self.link.reopen_port)
        except DomeLinkError as exc:
            log.info("%s: the port did not open again: %s", self.name, exc)
            self.off_report = replace(
                self.off_report, detail=f"the port did not open again after the stop: {exc}"
            )
        except BaseException:
            # a further stop while the port was being opened again: it ends here, nothing sent
            self.off_report = replace(
                self.off_report,
                detail="a further stop ended the reopening of the port a stop had cut short",
            )
            self._quiet_close()
            raise

    def _lit_at_boot(self) -> str | None:
        """The firmware's name if it lights every LED as its board boots (the Nab sketch)."""
        return self.link.boots_lit_firmware

    def _finish_boot(self) -> None:
        """Let a board the stop caught in its bootloader finish booting (to the end of the
        profile's boot wait begun when the port opened) before the all-off, which would be lost
        there; a link whose boot wait is over returns at once, and one that fails goes straight
        on to the all-off."""
        try:
            self._counted(self.link.finish_boot)
        except DomeLinkError as exc:
            log.info("%s: waiting for the board to boot failed: %s", self.name, exc)

    def _link_hint(self) -> str:
        """``settings.link_hint`` as the end of an advice sentence ("" when there is none)."""
        hint = self.settings.link_hint
        return f" ({hint})" if hint else ""

    def _reopened_hint(self) -> str:
        """The end of a failed connect's advice when the all-off after it reached the board
        only at the firmware's published baud rate: then that rate is established, not guessed."""
        report = self.off_report
        if report is None or report.reopened_at is None:
            return ""
        if report.outcome is not OffOutcome.ACKNOWLEDGED:
            return ""
        return (
            f"; reopened at {report.reopened_at} baud to switch it off, the board acknowledged "
            f"its all-off there: it talks at {report.reopened_at} baud"
        )

    def _attempt_off(
        self, when: str, after_open: bool = False, *, at_published_rate: bool = False
    ) -> None:
        """One all-off, whatever state the link is in; record what it established. One that
        met a reboot banner is sent once more (:meth:`_all_off_after_reboot`).

        ``after_open``: the port was opened by the connect that failed, which resets a board
        that resets on open; on a firmware that boots lit (``boots_lit``, the Nab sketch) a
        failed all-off then leaves every LED on if the board is that one, and is said so.

        ``at_published_rate`` (a failed connect where the board spoke nothing of its profile):
        on such a firmware, an all-off that went unanswered at a port rate other than the
        firmware's published one is sent again after reopening the port at that rate (the
        link's ``switch_off_at_published_rate``). At the wrong rate the all-off is garbage to the
        board, which the opening had lit whole: it was left so, the user told to cut its power.
        The reopening resets the board once more (lit while it boots), then switches it off.
        A port that sent no byte at all since it opened is not reopened (see
        :meth:`_not_reopened_silent`)."""
        lit_at_boot = self._lit_at_boot() if after_open else None
        try:
            self._counted(self.link.all_off)
        except DomeLinkError as first:
            exc = first
            if exc.fault is LinkFault.RESET and self.link.port_open:
                try:
                    self._all_off_after_reboot(exc, when)
                except DomeLinkError as again:
                    exc = again
                    self._failed_offs += 1  # the first, met by the banner (this one: below)
                except DeviceError as other:
                    log.info("%s: all off %s failed: %s", self.name, when, other)
                    self._failed_offs += 2  # the one the banner met and the one sent again
                    self.off_report = OffReport(
                        OffOutcome.SENT_UNCONFIRMED, str(other), boots_lit=lit_at_boot
                    )
                    return
                else:
                    return
            if exc.fault is LinkFault.FOREIGN:
                self._switch_off_foreign(when)
                return
            log.info("%s: all off %s failed: %s", self.name, when, exc)
            self._failed_offs += 1
            self.off_report = replace(_failed_off(exc), boots_lit=lit_at_boot)
            if at_published_rate and lit_at_boot and exc.fault is not LinkFault.DISCONNECTED:
                if self.link.bytes_heard:
                    self._switch_off_at_published_rate(lit_at_boot)
                else:
                    self._not_reopened_silent(lit_at_boot)
        except DeviceError as exc:
            log.info("%s: all off %s failed: %s", self.name, when, exc)
            self._failed_offs += 1
            self.off_report = OffReport(
                OffOutcome.SENT_UNCONFIRMED, str(exc), boots_lit=lit_at_boot
            )
        else:
            self.off_report = OffReport(
                self.link.off_outcome, when, on_time_s=self.link.light_window_s
            )
            self._off_went_through()

    def _off_went_through(self) -> None:
        """Have the all-off just recorded as gone through say how many all-offs failed before
        it (since the last that went through), then count afresh.

        Why: a session whose teardown all-off went unanswered printed "teardown problem: all
        LEDs off … no reply" and then, of the closing all-off the dome acknowledged, "lights
        are off", with nothing saying that this was another all-off, sent after the failed
        one; it read as a contradiction. The count is this policy's own record of its
        all-offs, so the order it states was established, not inferred from the messages."""
        if self._failed_offs and self.off_report is not None:
            self.off_report = replace(self.off_report, after_failed=self._failed_offs)
        self._failed_offs = 0

    def _all_off_after_reboot(self, reset: DomeLinkError, when: str) -> None:
        """The all-off once more after the one that met a reboot banner (found before it was
        written, or in its reply's place); records what it established, raises what it failed
        with, said with what happened to the first.

        Why: the banner says the firmware is up again on a port still open, and the reboot
        decides nothing safe by itself: most firmwares boot dark, but the Nab sketch boots with
        every LED lit. The single all-off had been given up there, and said "sent but not
        acknowledged" when it had not even been written; one more, acknowledged where the
        firmware does, establishes what the reboot left. Only once: a board that keeps
        rebooting is said so, and sent to its power supply."""
        first = "was not written" if not reset.sent else "was met by its boot banner"
        log.info(
            "%s: the board rebooted and the all-off %s %s: sending it once more",
            self.name,
            when,
            first,
        )
        try:
            self._counted(self.link.all_off)
        except DomeLinkError as again:
            raise DomeLinkError(
                again.device,
                f"the board rebooted and the first all-off {first}; the one sent again after "
                f"its boot banner failed too: {again.message}",
                again.command,
                again.fault,
                retryable=again.retryable,
                code=again.code,
                sent=again.sent,
            ) from again
        self.off_report = OffReport(
            self.link.off_outcome,
            f"{when}, sent again after the board rebooted",
        )
        self._off_went_through()

    def _not_reopened_silent(self, firmware: str) -> None:
        """Record why a port wholly silent since it opened is not reopened at the firmware's
        published rate (see :meth:`_attempt_off`).

        Why: a board of a firmware that boots lit prints its banner at every opening (the Nab
        sketch's ``setup()``), and at a wrong baud rate that banner still comes, as garbled
        bytes; a port that sent not one byte through the boot wait, the resent handshake and
        the all-off had no such board booting on it within the boot wait. Reopening it cost a
        second boot wait and reply timeout (7 s with the Nab profile) for an all-off that would
        reach nothing booted in time. It is said as the connect's advice (the link's
        ``silence_hint``) says it: a board slower to boot than the wait is silent through it
        too (the lights line had said no board was there, beside that advice)."""
        rate = getattr(self.link, "published_baudrate", None)
        if rate is None or self.off_report is None:
            return
        report = self.off_report
        self.off_report = replace(
            report,
            detail=(
                f"{report.detail}; not reopened at {rate} baud, the {firmware} firmware's "
                "published rate: not one byte came from the port since it opened, and that "
                "firmware's board prints its boot banner at every opening (garbled at a wrong "
                "baud rate), so none booted within the boot wait: this is another port, or a "
                "board slower to boot than boot_wait_s (see the connect's advice)"
            ),
        )

    def _switch_off_at_published_rate(self, firmware: str) -> None:
        """See :meth:`_attempt_off`; records what the second all-off established."""
        rate = getattr(self.link, "published_baudrate", None)
        switch = getattr(self.link, "switch_off_at_published_rate", None)
        if rate is None or switch is None:
            return
        log.info(
            "%s: reopening the port at %d baud, the %s firmware's published rate, to switch the "
            "board off (it boots with every LED lit)",
            self.name,
            rate,
            firmware,
        )
        try:
            outcome = self._counted(switch)
        except DomeLinkError as exc:
            log.info("%s: all off at %d baud failed: %s", self.name, rate, exc)
            self.off_report = replace(_failed_off(exc), boots_lit=firmware, reopened_at=rate)
            return
        self.off_report = OffReport(outcome, boots_lit=firmware, reopened_at=rate)

    def _switch_off_foreign(self, when: str) -> None:
        """Send the all-off of the firmware whose banner the board printed (the link's
        ``switch_off_foreign``: that all-off alone, acknowledged where that firmware
        acknowledges), never this profile's; record what it established.

        Why (a decision of the project's owners, hardware safety first): a Nab board, which
        boots with every LED on, refused for its banner under another profile had been left
        lit ("all-off could NOT be sent … switch the dome off at its power supply"), when the
        all-off of the firmware it had just named switches it off. A link that cannot send
        another firmware's all-off leaves the lights as unknown, as before."""
        switch = getattr(self.link, "switch_off_foreign", None)
        if switch is None:
            self.off_report = OffReport(
                OffOutcome.NOT_SENT,
                "the board on the port runs another firmware, to which this profile's all-off "
                "is other commands",
            )
            return
        firmware = getattr(self.link, "foreign_firmware", None) or "other"
        try:
            outcome = self._counted(switch)
        except DomeLinkError as exc:
            log.info("%s: the %s firmware's all-off %s failed: %s", self.name, firmware, when, exc)
            self.off_report = _failed_off(exc)
            return
        self.off_report = OffReport(
            outcome, f"the {firmware} firmware's own all-off, whose banner the board printed"
        )

    def _require_connected(self, command: str) -> DomeInfo:
        if self.info is None:
            raise DeviceError(self.name, "not connected; call connect() first", command)
        return self.info

    def _check_index(self, index: int, count: int) -> None:
        if isinstance(index, bool) or not isinstance(index, int | np.integer):
            raise DeviceError(self.name, f"LED index {index!r} is not an integer")
        if not 0 <= index < count:
            raise DeviceError(
                self.name,
                f"LED {index} does not exist: this dome has LEDs 0..{count - 1}",
                f"light LED {index}",
            )

    def _quiet_close(self) -> str | None:
        """Close the link, never raising; return what went wrong, as said (None: closed)."""
        try:
            self.link.close()
        except Exception as exc:  # closing must never mask the error that led here
            # said in words (a raw warning record had been printed mid-progress-bar), and
            # with no listener as a warning, which the command line says as a note: never lost
            text = (
                f"{self.name}: its port did not close cleanly: {exc}. It is opened anew when "
                "next needed; if that fails, unplug the dome's USB cable and plug it in again."
            )
            if text in self.close_errors:  # once: a reconnection's attempts close it each
                log.info("%s", text)
                return text
            self.close_errors.append(text)
            if self._say is not None:
                self._say(text)
            else:
                log.warning("%s", text)
            return text
        return None


#: Faults of a board that may not be the one the profile describes (or no board at all).
_NOT_ITS_BOARD = (LinkFault.TIMEOUT, LinkFault.GARBLED, LinkFault.MISMATCH)


def _open_failure_head(message: str) -> str:
    """The system's reason a port could not be opened, for the lights line: ``message`` up to
    its first ``;`` outside parentheses, and a pointer to the error for the ports present.

    Why: a missing port's error carries the serial ports present now and how to set one
    (:mod:`rti_rig.drivers.ports_present`), a paragraph the lights line had repeated word for
    word beside the error that says it (at every ``run`` and ``check`` on a port gone). The
    pointer only where the error lists them (a listing that failed is not a list)."""
    head = first_clause(message)
    if head == message or "serial ports present now" not in message:
        return message
    return f"{head}; the error says which serial ports are present now"


def _lost_after_opening(exc: DomeLinkError) -> bool:
    """The port opened, then vanished (a USB drop): not a port that could not be opened."""
    return exc.fault is LinkFault.DISCONNECTED and exc.command != "open port"


def _failed_off(exc: DomeLinkError) -> OffReport:
    """A failed all-off: not sent if the port was gone or it failed before it was written
    (``exc.sent``: a reboot banner found waiting), else sent but unconfirmed.

    Why: a boot banner found before the all-off was written failed it with a reset fault, and
    the lights line said "all-off sent but not acknowledged" of bytes never written."""
    if exc.fault is LinkFault.DISCONNECTED:
        return OffReport(OffOutcome.NOT_SENT, exc.message)
    if not exc.sent:
        return OffReport(
            OffOutcome.NOT_SENT, f"{exc.fault}: {exc.message}; it was not written to the port"
        )
    return OffReport(OffOutcome.SENT_UNCONFIRMED, f"{exc.fault}: {exc.message}")


def lights_state_sentence(source: DomePolicy) -> str:
    """What is known about a dome's lights after it was closed (for messages).

    A source that never began a connect (``reached`` None: a refusal of ``--out`` or the disk
    came first) never opened its port, so nothing can be lit by it: it had been told to "check
    the dome's lights" beside the refusal. Its record is read by name (every caller holds a
    :class:`DomePolicy`): ``getattr`` probes had answered "never reached" for a misspelt one."""
    report = source.off_report
    if report is None:
        if source.reached is None:
            return "nothing was lit: the dome's port was never opened"
        return "no all-off was attempted (the dome was never reached): check the dome's lights"
    sentence = str(report.sentence())
    window = source.came_back_after_give_up
    if window is not None:
        sentence += (
            f" (the dome came back after the reconnection gave up: its USB link was away longer "
            f"than the {window:.1f} s of reconnection attempts; check the USB cable, the hub and "
            f"the dome's power, or {source._window_keys()})"
        )
    return sentence


# ----------------------------------------------------------------------------- self test


@dataclass(frozen=True)
class LedCheck:
    index: int
    ok: bool
    message: str = ""


@dataclass
class SelfTestReport:
    """What ``rti-rig check`` prints: identity, per-LED results, what recovery was needed."""

    name: str
    firmware: DomeInfo | None
    led_count: int
    checks: list[LedCheck] = field(default_factory=list)
    elapsed_s: float = 0.0
    stats: DomeStats | None = None
    aborted: str | None = None
    #: LEDs the test meant to step through (all of them unless a subset was asked for).
    planned: int = 0
    #: Wall-clock seconds each successful ``light`` call took (the command's round trip over
    #: the real link, whatever clock the rig uses): a measured ``light_switch_s``.
    light_latency_s: list[float] = field(default_factory=list)
    #: What is known about the lights at the end (the last all-off's outcome).
    lights_state: str = ""
    #: Whether the firmware answers a light command: if not, a step "passes" when it was sent
    #: without error, and only a person watching the dome knows whether the LED lit.
    light_confirmed: bool = True
    #: Whether the firmware senses LED current (refuses a dead LED): if not, an acknowledged
    #: step says only that the board took the command, not that the LED lit.
    senses_current: bool = True
    #: How far the connect got (:attr:`DomePolicy.reached`); None: not a dome policy.
    reached: str | None = None
    #: The built-in firmware whose boot banner the board printed when it is not the profile's
    #: (the link's ``foreign_firmware``); None: none seen.
    foreign_firmware: str | None = None
    #: How many of ``stats.recovered`` the connect itself recovered from: the walk's own come
    #: after (a banner later than the boot wait, at the port's opening, is the connect's: a
    #: slow bootloader, not a board that rebooted by itself during the walk).
    recovered_at_connect: int = 0
    #: A boot banner later than the profile's boot wait (the link's ``slow_boot_advice``: a
    #: slow bootloader and the ``boot_wait_s`` to set), said in the report: it had reached
    #: stderr alone, beside a "RESULT: PASS" that a user reads as nothing to change.
    slow_boot: str | None = None
    #: A simulated dome (its state the simulation's): no firmware to name and no command to
    #: time. Why: ``check rig_configs/simulated_dome.toml`` said "unknown firmware, 48 LEDs"
    #: and "light command round trip: median 0.00 ms (wall clock)", as if a board had not
    #: been identified and had answered instantly, beside a walk timed on the simulation's
    #: clock (the arm's check says its clock, the dome's did not).
    simulated: bool = False
    #: The rig config checked, as one shell word ("": not known), for the session its advice
    #: names: the advice had said ``rti-rig fit S --out FOLDER``, no command that ran pasted.
    rig_config: str = ""
    #: At what level the walk lit each LED, as the report says it ("": not said, a walk of
    #: no dome policy). Why: a dome that cannot dim is walked fully on, not at the check's
    #: intensity, and a PASS had not said which of the two it established.
    level_said: str = ""

    @property
    def failed(self) -> list[LedCheck]:
        return [c for c in self.checks if not c.ok]

    @property
    def ok(self) -> bool:
        return (
            self.aborted is None
            and not self.failed
            and self.planned > 0
            and len(self.checks) == self.planned
        )

    @property
    def median_light_latency_s(self) -> float | None:
        lat = self.light_latency_s
        return float(np.median(lat)) if lat else None

    def _dark_image_advice(self) -> str:
        """The session of every LED, and the fit whose QA names a dark image, as commands that
        run pasted: the rig config checked, and folders free in the working folder when said
        (``S`` and ``FOLDER``, pasted, had made folders of those names)."""
        fit_options = "--no-ptm --no-hsh --no-normals"
        if not self.rig_config:
            return f"shoot a session of every LED and fit it with {fit_options}"
        session = free_name(Path("led-check"), folder=True)
        fit = free_name(Path(f"{session.name}-fit"), folder=True)
        return (
            f"shoot a session of every LED (`rti-rig run {self.rig_config} --out "
            f"{shell_word(str(session))}`) and fit it (`rti-rig fit {shell_word(str(session))} "
            f"--out {shell_word(str(fit))} {fit_options}`)"
        )

    def lines(self) -> list[str]:
        fw = (
            f"{self.firmware.firmware_id} {self.firmware.version}"
            if self.firmware
            else "no firmware (a simulation)"
            if self.simulated
            else "unknown firmware"
        )
        if self.foreign_firmware is not None:
            # another firmware's board: the profile's name and the config's LED count in the
            # heading ("rti-dome-m, 8 LEDs" over "LEDs stepped: 0") had read as a board that
            # was identified and counted, and the light commands sent before its banner showed
            # were other keys to it, not steps of this dome
            board = (
                f"{self.firmware.firmware_id} board"
                if self.firmware
                else "board of the rig config's profile"
            )
            sent = len(self.light_latency_s)
            out = [
                f"{self.name}: not a {board}: it printed the boot banner of the "
                f"{self.foreign_firmware} firmware (see ABORTED below); its LED count is unknown",
                "no LED stepped"
                + (
                    f" ({sent} light command{'s' if sent != 1 else ''} of this profile reached "
                    "it before its banner showed: other keys to that firmware)"
                    if sent
                    else ""
                ),
            ]
        elif self.aborted and not self.checks and self.reached in _REACHED:
            # the port opened: say how far the connect got, not "not reached" (a board whose
            # banner and init all-off came through, then whose next all-off's reply was lost,
            # had been reported "not reached")
            out = [f"{self.name}: {_REACHED[self.reached]}; no LED stepped (see ABORTED below)"]
        elif self.aborted and self.firmware is None and not self.led_count and not self.checks:
            # never reached: "unknown firmware, 0 LEDs" and "LEDs stepped: 0" had read as a
            # dome that answered with no LEDs (the config's 48 were never asked about)
            out = [f"{self.name}: not reached, no LED stepped (see ABORTED below)"]
        else:
            # a firmware that reports no count: say whose count it is (the config's), never
            # as if the board had said it
            count = (
                self.firmware.led_count_heading()
                if self.firmware is not None and self.firmware.led_count == self.led_count
                else f"{self.led_count} LEDs"
            )
            out = [f"{self.name}: {' '.join(fw.split())}, {count}"]
            passed = sum(c.ok for c in self.checks)
            out.append(
                f"LEDs stepped: {len(self.checks)}, {self._passed_as()}: {passed}"
                + f", failed: {len(self.failed)} in {self.elapsed_s:.2f} s on the rig's clock"
            )
            if self.level_said and self.checks:
                out.append(f"  {self.level_said}")
            if self.light_confirmed and not self.senses_current and passed:
                out.append(
                    "  whether each LED lights cannot be sensed by this firmware (it measures "
                    "no LED current, so a dead LED is acknowledged too): look at the dome "
                    f"during the check, or {self._dark_image_advice()}, whose QA names a dark "
                    "image"
                )
        out += [f"  LED {c.index}: {c.message}" for c in self.failed]
        out += self._index_base_hint()
        if self.light_latency_s and self.foreign_firmware is None and not self.simulated:
            lat = np.asarray(self.light_latency_s) * 1000
            out.append(
                f"light command round trip: median {np.median(lat):.2f} ms, "
                f"max {lat.max():.2f} ms (wall clock)"
            )
        if self.stats is not None:
            s = self.stats
            out.append(
                f"recovery: {s.retries} retries, {s.reconnects} reconnects, "
                f"{s.rehandshakes} re-handshakes"
            )
            out += _recovered_board_faults(s.recovered[self.recovered_at_connect :])
        if self.slow_boot:
            out.append(
                f"slow boot: {self.slow_boot}; the commands were sent again after the banner "
                "and the check went on, but each session on this board meets the same wait"
            )
        if self.aborted:
            out.append(f"ABORTED: {self.aborted}")
        if self.lights_state:
            out.append(f"lights: {self.lights_state}")
        if self.ok and not self.light_confirmed:
            # the firmware answers no light command: the same board is "passed" by any board,
            # or none, on this port (another firmware's board had passed as this one)
            out.append(
                "RESULT: SENT, NOT VERIFIED (this firmware answers no light command: watch the "
                "dome during the check; each LED should light in turn)"
            )
        elif self.ok and not self.senses_current:
            # PASS of what was established: the board and its replies, not the LEDs' light
            out.append(
                "RESULT: PASS (LEDs acknowledged; lit not verified: board cannot sense current)"
            )
        else:
            out.append("RESULT: " + ("PASS" if self.ok else "FAIL"))
        return out

    def _index_base_hint(self) -> list[str]:
        """A line where the one LED refused as out of the board's range is the first or the
        last: the board numbers its LEDs from another base than the config sends, and every
        other LED stepped lit its neighbour.

        Why: a board numbered from 0 under a config's ``index_base = 1`` "passed" 47 LEDs,
        each the next one, and failed LED 47 as if it alone were dead."""
        if len(self.failed) != 1 or len(self.checks) < 3:
            return []
        failed = self.failed[0]
        ends = {min(c.index for c in self.checks), max(c.index for c in self.checks)}
        if failed.index not in ends or "out of range" not in failed.message:
            return []
        return [
            f"  only LED {failed.index}, at the end of the range, was out of the board's range: "
            "either the board numbers its LEDs from another base than the rig config sends "
            "(the framed and binary profiles' index_base, 0 or 1: then every other LED stepped "
            "lit its neighbour; set index_base to the board's), or the config lists more LEDs "
            "than the board has (then the others are right; list the board's own)"
        ]

    def _passed_as(self) -> str:
        """What a step that ended without error established, as the walk's count names it:
        "passed" only where the firmware would have refused a dead LED.

        Why: a board that senses no current (the Nab sketch and every described firmware)
        acknowledges a dead LED as it does a good one, and "passed: 12 … PASS" had claimed
        12 LEDs that lit, of a dome with a dead one."""
        if not self.light_confirmed:
            return "sent without error"
        return "passed" if self.senses_current else "acknowledged by the board"


def _recovered_board_faults(recovered: list[str]) -> list[str]:
    """A line for a board that rebooted or dropped off the USB bus during the check's walk (after
    the connect) and was recovered from (the walk went on).

    Why: a reboot at an all-off (no LED meant lit) was recovered and the check ended "RESULT:
    PASS" with only "1 re-handshakes" to show for it, where a reboot while an LED was lit
    failed the check saying to look at the power supply and the USB cable: a board that
    reboots or drops off by itself will do so in a session too, and stop it there."""
    what = {"reset": "rebooted", "disconnected": "dropped off the USB bus"}
    seen: dict[str, list[str]] = {}
    for entry in recovered:
        command, _, fault = entry.rpartition(": ")
        if fault in what:
            seen.setdefault(what[fault], []).append(command)
    return [
        f"the board {event} during the check (at {', '.join(map(repr, commands))}) and the "
        "check went on; a board that does so by itself points to its power supply or its USB "
        "cable: check them (in a session, one that comes while an LED is lit stops the run)"
        for event, commands in seen.items()
    ]


#: What each stage of :attr:`DomePolicy.reached` established, as the check's first line says it.
_REACHED = {
    "opened": "port opened, but nothing came back that its protocol profile reads",
    "answered": (
        "port opened and the board answered in its protocol profile, but the connection did "
        "not complete"
    ),
    "connected": (
        "connected (the board answered in its protocol profile), but the all-off that starts "
        "the walk from the safe state failed"
    ),
}


def _ended_by_slow_boot(error: BaseException | None) -> bool:
    """Whether ``error`` is a slow boot's :class:`DomeLinkError` (``slow_boot`` set), or was
    raised from one (``raise … from``, the policy's way of restating a link error with its
    advice added): the check then ended on it and its advice is already the error said.

    Why: this had been decided by looking for the link's advice text inside the error's
    message, so rewording either (or restating the error without quoting it) changed whether
    the report said "the check went on" of a check the slow boot had ended. Only explicit
    causes are followed: an error merely raised while handling a slow boot (``__context__``)
    is a fault of its own, after which the slow boot's advice is still news."""
    seen: set[int] = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, DomeLinkError) and error.slow_boot:
            return True
        seen.add(id(error))
        error = error.__cause__
    return False


def _walk_level(source: DiscreteLightSource, intensity: float) -> tuple[float, str]:
    """The intensity the check's walk lights each LED at, and the words that say it.

    A link that cannot dim (the ``framed`` profile with ``send_level = false``, every on/off
    firmware) is walked fully on: the only level its light command can ask for. Why: the walk
    had asked every LED of a framed dome without levels for 0.2, which its driver refuses
    ("configured without intensity"), and the check failed each LED of a working dome. The
    thermal and duty limits still hold: :meth:`DomePolicy.light` applies them at any level."""
    if not isinstance(source, DomePolicy):
        return intensity, ""
    if source.link.can_dim:
        scaled = (
            " (each scaled by its intensity_correction)"
            if source.settings.intensity_correction is not None
            else ""
        )
        return intensity, f"each LED lit at intensity {intensity:g}{scaled}"
    instead = "" if intensity >= 1.0 else f", not the check's {intensity:g}"
    codec = getattr(source.link, "codec", None)
    if getattr(codec, "profile", None) == "framed":
        why = "the framed profile with send_level = false sends no level in its light frames"
    else:
        firmware = source.link.firmware_name or "dome's"
        why = f"the {firmware} firmware's light command carries no level"
    return 1.0, f"each LED lit fully on (intensity 1{instead}): {why}"


def self_test(
    source: DiscreteLightSource,
    clock: Clock,
    *,
    intensity: float = 0.2,
    settle_s: float = 0.05,
    leds: Sequence[int] | None = None,
) -> SelfTestReport:
    """Handshake, then light each LED in turn (confirming with the firmware when it can), at
    ``intensity``, or fully on where the link cannot dim (:func:`_walk_level`, said in the
    report's ``level_said``).

    Connects and closes ``source`` itself. An error about one LED is recorded and the test moves
    on; any other error aborts the walk (the dome is switched off in every case).
    """
    started = clock.now()
    report = SelfTestReport(name=source.name, firmware=None, led_count=0)
    ended_by: DeviceError | None = None
    link = source.link if isinstance(source, DomePolicy) else None
    # a source with no link (no firmware to answer) is reported as before: its steps passed
    report.light_confirmed = True if link is None else link.light_confirmed
    report.senses_current = True if link is None else link.senses_led_current
    report.simulated = isinstance(source, KnownStateLightSource)
    intensity, report.level_said = _walk_level(source, intensity)
    if isinstance(source, DomePolicy):
        source.lights_images = False  # an LED lost to a reboot spoils no image here
    try:
        source.connect()
        report.led_count = source.light_count()
        if isinstance(source, DomePolicy):
            report.firmware = source.info
            report.stats = source.stats
            report.recovered_at_connect = len(source.stats.recovered)
        order = list(range(report.led_count)) if leds is None else list(leds)
        report.planned = len(order)
        for i in order:
            try:
                t0 = time.perf_counter()
                source.light(i, intensity)
                report.light_latency_s.append(time.perf_counter() - t0)
                clock.sleep(settle_s)
                if isinstance(source, DomePolicy) and source.link.can_query:
                    lit, _ = source.lit_state()
                    if lit != i:
                        report.checks.append(LedCheck(i, False, f"firmware reports LED {lit} lit"))
                        source.all_off()
                        continue
                source.all_off()
                report.checks.append(LedCheck(i, True))
            except DomeLedError as exc:
                report.checks.append(LedCheck(i, False, str(exc)))
    except DeviceError as exc:
        report.aborted = str(exc)
        ended_by = exc
    finally:
        if isinstance(source, DomePolicy):
            report.reached = source.reached  # before close() forgets the connection
        report.foreign_firmware = getattr(link, "foreign_firmware", None)
        slow = getattr(link, "slow_boot_advice", None)
        if isinstance(slow, str) and not _ended_by_slow_boot(ended_by):
            report.slow_boot = slow  # recovered from; one that ended the check is its error
        if isinstance(source, DomePolicy):
            source.ending()  # a reopening now is for the closing all-off, said so
        try:
            source.close()
        except DeviceError as exc:
            report.aborted = report.aborted or str(exc)
        report.elapsed_s = clock.now() - started
        if isinstance(source, DomePolicy):
            report.lights_state = lights_state_sentence(source)
            source.lights_images = True  # a session on the same dome takes images again
    return report
