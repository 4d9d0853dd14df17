"""Lighting policy over the two kinds of light source.

The controller speaks one small vocabulary — check a step, light it, turn it off, go safe — and
these adapters translate it for a dome (discrete LEDs) or an arm (a lamp moved to a direction).
They also say what *actually* ran: the calibrated direction of the LED fired, or the direction the
arm reached, which is what the session's `.lp` records.
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from rti_rig.core.clock import Clock
from rti_rig.core.deferred_signals import signals_deferred, stop_words
from rti_rig.core.devices import (
    DiscreteLightSource,
    KnownStateLightSource,
    LightCarrier,
    ReadBackCarrier,
)
from rti_rig.core.errors import DeviceError, MoveCancelled, StopIncomplete, UnheldJoint
from rti_rig.core.geometry import angle_between_deg
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.core.schedule import LightStep
from rti_rig.core.shell_words import shell_word
from rti_rig.runtime.arm_end import ArmEnd, left_end, park_end
from rti_rig.runtime.dome_policy import DomePolicy, DutyWait

#: A dome step's direction must match its LED's calibrated direction this closely (degrees).
LED_MATCH_TOLERANCE_DEG = 0.5

#: :meth:`Lighting.lit_limit_said` of a light with no limit (never in a message: it is asked
#: only of a light whose :meth:`Lighting.lit_limit_s` is not None).
NO_LIT_LIMIT = "no limit on how long a light stays lit"


#: Why a dome step's LED is not where its direction says (a resume on a dome renumbered since
#: rewords it: ``rti_rig.app.usecases.session._refused_on_changed_rig``)
ANOTHER_LAYOUT = "the plan was made for another dome layout"


@dataclass(frozen=True)
class ActualLight:
    """The light that really lit an image."""

    direction: tuple[float, float, float]
    led: int | None = None


class Lighting(Protocol):
    name: str

    def connect(self) -> None: ...

    def close(self) -> None: ...

    def problem(self, step: LightStep) -> str | None: ...

    def set(self, step: LightStep) -> ActualLight: ...

    def off(self) -> None: ...

    def safe(self, emergency: bool = False) -> list[str]: ...

    def lit_limit_s(self) -> float | None:
        """How long one light may stay lit at a time (a dome's ``max_on_s``, or a timed
        firmware's shorter window), None when nothing limits it (an arm's lamp, a simulated
        dome, a dome the camera steps). Each implementation answers it: the controller had
        guessed with ``getattr(rig.lighting, "lit_limit_s", None)``, which a rename would have
        silently answered "no limit", and the busy camera's relight would have lit past it."""
        ...

    def lit_limit_said(self) -> str:
        """What sets :meth:`lit_limit_s`, as a message names it (``max_on_s = 8 s``); asked
        only of a light that has a limit."""
        ...

    # What follows is answered by every lighting too, a light without the ability giving the
    # default each names: the controller had asked each with ``getattr``, which a rename would
    # have silently answered with that default.

    def hold(self) -> None:
        """Lights off, the link kept open for the next :meth:`connect` where it can be (a
        dome's port); :meth:`close` otherwise."""
        ...

    def off_said(self) -> str | None:
        """What the last all-off established, as recorded (None: no record kept)."""
        ...

    def cool_down_s(self, step: LightStep, at: float) -> float:
        """How long after ``at`` the step's light must still cool before it may light (0: no
        thermal guard)."""
        ...

    def listen(self, say: Callable[[str], None] | None) -> None:
        """Have the lights say through ``say`` what a user must know as it happens: a dome's
        reopening of its lost link, an arm's search for its servos at other baud rates or a
        torque kept on at its close (a light with nothing such to say says nothing)."""
        ...

    def check_held(self) -> None:
        """After a capture: raise unless the light still is where it was recorded (an arm's
        pose; a light that cannot move or cannot tell does nothing)."""
        ...

    def resends(self) -> tuple[dict[str, list[str]], str | None]:
        """The manifest's record of commands resent after a fault that then went through, and
        the line that counts them for the user (nothing and None: none, or none counted)."""
        ...

    def reconnections(self) -> list[dict[str, object]]:
        """Each reopening of the lights' lost link so far, for the manifest (none: [])."""
        ...

    def port_close_failure(self) -> str | None:
        """How the last :meth:`close` failed to release the lights' port, in the words said
        to the user as it happened (None: it closed cleanly, or the lights have no port of
        their own to close: an arm's carrier raises its close's failures)."""
        ...

    @property
    def link_open(self) -> bool:
        """Whether the lights' link to the host is open now, so that :meth:`safe` can be sent
        on it without opening it (a session closed before the controller's teardown ran makes
        the lights safe only then). Each implementation answers it: the caller had guessed
        with ``getattr(lighting, "link_open", False)``, which a renamed or mistyped attribute
        would have silently answered False."""
        ...


class DomeLighting:
    """A dome: each step names an LED whose calibrated direction is the recorded one."""

    def __init__(self, source: DiscreteLightSource, geometry: DomeGeometry) -> None:
        self.source = source
        self.geometry = geometry
        self.name = source.name

    @property
    def policy(self) -> DomePolicy | None:
        """The runtime's own dome policy this lighting drives (a dome on a port, real or
        emulated), or None for a source without one (the simulated dome: no port to lose or
        hold, no resends, no thermal guard, no all-off outcome to record).

        Why: each ability below is asked of it by name, typed, and answers its documented
        default for None on purpose. They had been guessed at with ``getattr`` on the source
        (``hold``, ``lit_limit_s``, ``guard``, ``off_report``, ``stats``…), which a renamed or
        misspelt attribute would have silently answered "none": a dome never held open, no
        thermal limit, no resends to report."""
        return self.source if isinstance(self.source, DomePolicy) else None

    @property
    def known_state(self) -> KnownStateLightSource | None:
        """The source, when it declares that its lit state is known exactly (the simulated
        dome): its link and what its last commands left lit are then asked of it by name."""
        return self.source if isinstance(self.source, KnownStateLightSource) else None

    def connect(self) -> None:
        self.source.connect()
        if self.source.light_count() != self.geometry.count:
            raise DeviceError(
                self.name,
                f"reports {self.source.light_count()} LEDs but the rig config describes "
                f"{self.geometry.count}: fix the config's LED layout",
                "connect",
            )

    def close(self) -> None:
        self.source.close()

    def duty_wait(self) -> DutyWait | None:
        """How long the dome's LEDs waited dark for its duty limit; None for a source with no
        thermal guard (a simulated dome). Why typed: the run's time line had guessed at the
        source's ``stats`` and ``settings`` with ``getattr``, which a rename would have
        silently turned into "never waited"."""
        policy = self.policy
        return None if policy is None else policy.duty_wait()

    def check_held(self) -> None:
        """Nothing to check: an LED does not move during a capture (what it lit is the
        dome's all-off's and the thermal guard's to say)."""

    def hold(self) -> None:
        """Lights off, the dome's port kept open for the next :meth:`connect` where its driver
        can (a board that resets on open boots lit: the Nab sketch), closed otherwise."""
        policy = self.policy
        if policy is None:
            self.source.close()
        else:
            policy.hold()

    def problem(self, step: LightStep) -> str | None:
        if step.led is None:
            return "a dome step must name an LED (snap the plan to the dome's LEDs)"
        if not 0 <= step.led < self.geometry.count:
            return f"LED {step.led} does not exist: this dome has LEDs 0..{self.geometry.count - 1}"
        off = float(angle_between_deg(step.direction, self.geometry.directions[step.led]))
        if off > LED_MATCH_TOLERANCE_DEG:
            return (
                f"planned direction is {off:.2f}° from LED {step.led}'s calibrated direction: "
                f"{ANOTHER_LAYOUT}"
            )
        return None

    def set(self, step: LightStep) -> ActualLight:
        assert step.led is not None
        self.source.light(step.led, step.intensity)
        d = self.geometry.directions[step.led]
        return ActualLight((float(d[0]), float(d[1]), float(d[2])), step.led)

    def off(self) -> None:
        self.source.all_off()

    def lit_limit_s(self) -> float | None:
        """How long one LED may stay lit (the thermal guard's ``max_on_s``, or a timed
        firmware's shorter window: the LED is dark after it whatever the host does), None
        when the source sets no limit (a simulated dome).

        The controller switches the LED off while a busy camera is awaited past this, and
        lights it again for the shot (:func:`rti_rig.runtime.controller.shoot_step`)."""
        policy = self.policy
        return None if policy is None else float(policy.lit_limit_s())

    def lit_limit_said(self) -> str:
        """What sets :meth:`lit_limit_s`, as a message names it (``max_on_s = 8 s``)."""
        policy = self.policy
        return NO_LIT_LIMIT if policy is None else str(policy.lit_limit_said())

    def cool_down_s(self, step: LightStep, at: float) -> float:
        """How long after ``at`` (on the rig's clock) the step's LED must still cool before
        its duty limit lets it light again (0: it may light at ``at``), as the dome's thermal
        guard will wait in ``set``: said to the user before a wait in the dark, which that
        cool-down lengthens."""
        policy = self.policy
        if policy is None or step.led is None:
            return 0.0
        return max(0.0, float(policy.guard.earliest_start(step.led, at)) - at)

    def off_said(self) -> str | None:
        """What the last all-off established, as the dome policy recorded it
        (``"acknowledged"``, ``"sent-no-ack"``, ``"self-timed"``…), None when it keeps no
        record: a step's journal says what was established, never more."""
        policy = self.policy
        report = None if policy is None else policy.off_report
        return None if report is None else str(report.outcome)

    def safe(self, emergency: bool = False) -> list[str]:
        self.ending()  # a teardown's all-off: a port lost in it is not said to let things go on
        return attempt_all([("all LEDs off", self.source.all_off)])

    def listen(self, say: Callable[[str], None] | None) -> None:
        """Have the dome say through ``say`` each reopening of its lost port and its outcome,
        as it happens (a source that never reopens a port says nothing)."""
        policy = self.policy
        if policy is not None:
            policy.listen(say)

    def ending(self) -> None:
        """The command tears down from here: a reopening of the dome's port is then said as
        being for the closing all-off, never as "the session goes on"."""
        policy = self.policy
        if policy is not None:
            policy.ending()

    def resends(self) -> tuple[dict[str, list[str]], str | None]:
        """The manifest's ``dome_resent`` (each fault resent after whose command then went
        through, ``"<command>: <fault>"``) and the one line that counts them for the user;
        nothing and None when none was resent."""
        policy = self.policy
        if policy is None:
            return {}, None
        found, line = list(policy.stats.recovered), policy.resends_said()
        return ({"dome_resent": found} if line is not None else {}), line

    def reconnections(self) -> list[dict[str, object]]:
        """Each reopening of the dome's lost port so far (what was lost, the outcome), for the
        session's manifest: the user is told of it in a line, the detail is kept there."""
        policy = self.policy
        return [] if policy is None else list(policy.stats.reconnections)

    def port_close_failure(self) -> str | None:
        """How the dome's last close failed to release its port (the policy says it as it
        happens and never raises it); None for a clean close or a simulated dome."""
        policy = self.policy
        return None if policy is None else policy.close_failure

    @property
    def link_open(self) -> bool:
        """Whether the dome's port is open now (connected, or held open after metering): an
        all-off can then be sent without opening it, which may reset a board that boots lit.
        A simulated dome's is open while it is connected, as a real dome's port is: a dry run
        rehearses the all-off a session closed before its teardown sends (it had answered
        False, and such a close left the simulated dome lit, said as "switched off")."""
        policy = self.policy
        if policy is not None:
            return bool(policy.link.port_open)
        known = self.known_state
        return False if known is None else bool(known.link_open)


def park_check(config: str) -> str:
    """The command that parks an arm and does nothing else: ``rti-rig check CONFIG
    --park-only``, the config's path as shell words, so that it pastes and runs.

    Why: the run's end said "park it with 'rti-rig check'", a command that, pasted, is refused
    for its missing RIG_CONFIG, while the error above it named the config in full; and the
    plain check it then named walks every self-test pose before it parks, eight moves near the
    object for a user who asked for one. Every arm is built from a rig config
    (:class:`ArmLighting` requires it), so there is no ``RIG_CONFIG`` template to fall back to."""
    return f"rti-rig check {shell_word(config)} --park-only"


class ArmLighting:
    """An arm: move, then lamp on; the reached direction is the recorded one.

    Going safe always switches the lamp off and stops motion. Parking is a *move*, so it follows
    policy: after a session (completed, cancelled or failed) the arm parks unless
    ``park_after_session`` is off; after an emergency stop it stays where it stopped unless
    ``park_on_emergency`` is on, because moving a just-stopped arm near an object is what an
    emergency stop is meant to prevent.

    Whatever the policy, an arm whose own move or lamp failed (a servo fault such as an
    overload — "the arm is blocked" —, a move timeout, a servo that stopped answering), or whose
    stop did not hold every joint, is not parked: the park is a move sent to both joints, and
    it had driven the healthy joint round while the faulty one hung limp (the self-test,
    :mod:`rti_rig.runtime.arm_check`, already kept this rule). :attr:`end` says why it was not
    parked (a park not attempted by this rule is no teardown failure: nothing failed).
    """

    def __init__(
        self,
        carrier: LightCarrier,
        park_after_session: bool = True,
        park_on_emergency: bool = False,
        *,
        config: str,
        clock: Clock | None = None,
    ) -> None:
        self.carrier = carrier
        #: the rig's clock, to time the teardown's park (None: not timed)
        self.clock = clock
        #: how long the last :meth:`safe`'s park took on the rig's clock (None: no park begun,
        #: or no clock): a session's time line says it beside the moves to the lights, which
        #: had left the park's seconds of the session's time unaccounted for
        self.park_s: float | None = None
        #: whether that park reached the park pose (False: stopped or failed part-way, its
        #: seconds still spent): words must not call a park cut short "parking it"
        self.park_finished = False
        self.name = carrier.name
        #: the rig config's path, named in the check that parks the arm after a failure
        #: ("park it with 'rti-rig check'" had named no config: pasted, it was refused);
        #: required, so that no hint falls back to a ``RIG_CONFIG`` template
        self.config = config
        self.park_after_session = park_after_session
        self.park_on_emergency = park_on_emergency
        #: the arm's own failure since the last connect (a move or the lamp): no park after it
        self.arm_failure: Exception | None = None
        #: where the last :meth:`safe` left the arm, as read back (None: not gone safe yet)
        self.end: ArmEnd | None = None
        #: the signal (SIGINT, SIGTERM) that stopped the last :meth:`safe`'s park, if one did
        self.stopped_by: int | None = None
        #: the first signal held by the running :meth:`safe`, whether or not a park was due
        self._stop_asked: int | None = None
        #: the last :meth:`connect` raised (the arm was never reached): no park, no end
        self.connect_failed = False
        #: the teardown commands ("lamp off", "stop") the last :meth:`safe` could not send: a
        #: dead port (an unplugged adapter) had been reported as "lamp off and stop were
        #: requested", of requests that never left the computer
        self.not_sent: tuple[str, ...] = ()
        #: the joints the last :meth:`safe`'s failed stop did not hold, as read (a servo that
        #: shut itself off after an overload is limp: the lights line had said it held its goal)
        self.unheld: tuple[UnheldJoint, ...] = ()

    def resends(self) -> tuple[dict[str, list[str]], str | None]:
        """The manifest's ``arm_resent`` (each command sent once more after its status packet
        was lost or damaged, then answered) and the one line that counts them for the user;
        nothing and None when none was (or the carrier keeps no count: one that does not
        read its servos back, :class:`rti_rig.core.devices.ReadBackCarrier`)."""
        carrier = self.read_back
        found, line = ([], None) if carrier is None else carrier.resends()
        return ({"arm_resent": found} if found else {}), line

    def listen(self, say: Callable[[str], None] | None) -> None:
        """Have the arm say through ``say`` what a user must know as it happens (its search
        for the servos at other baud rates, a torque kept on at the close, a second failure
        while making it safe); a carrier with nothing to say ignores it."""
        if self.read_back is not None:
            self.read_back.listen(say)

    @property
    def read_back(self) -> ReadBackCarrier | None:
        """The carrier, when it declares that it reads its servos back (a Dynamixel arm), or
        None (the simulated arm): its resends, its close's torque release and its check that
        the pose held are then asked of it by name, and a carrier without them gets the
        defaults documented on each method, on purpose (they had been guessed at with
        ``getattr``, which a misspelt name answered "none")."""
        return self.carrier if isinstance(self.carrier, ReadBackCarrier) else None

    def lit_limit_s(self) -> None:
        """None: an arm's lamp has no thermal limit the controller keeps."""
        return None

    def lit_limit_said(self) -> str:
        """No limit to name (:meth:`lit_limit_s` is None)."""
        return NO_LIT_LIMIT

    def hold(self) -> None:
        """An arm keeps no link open between commands: :meth:`close` (lamp off, stop)."""
        self.close()

    def off_said(self) -> None:
        """None: a lamp-off's outcome is not recorded apart (a failure raises)."""
        return None

    def cool_down_s(self, step: LightStep, at: float) -> float:
        """0: an arm's lamp has no thermal guard here."""
        return 0.0

    def reconnections(self) -> list[dict[str, object]]:
        """[]: a carrier does not reopen a lost port mid-session."""
        return []

    def port_close_failure(self) -> None:
        """None: the carrier's close raises what failed (its port's release included)."""
        return None

    def connect(self) -> None:
        self.arm_failure = None
        self.end = None
        self.connect_failed = False
        try:
            self.carrier.connect()
        except BaseException:
            self.connect_failed = True
            raise

    def close(self) -> None:
        """Close the carrier, then record in :attr:`end` what the close did to its torque.

        Why: a carrier with ``torque_policy = "release_on_close"`` switches its torque off at
        the close when it finds the arm at its park pose, after :meth:`safe` has read the arm
        back; ``run`` then said "parked" with no word of the release, and "held where it
        stopped, torque on" of a park a Ctrl-C stopped near the park pose, an arm whose
        close had just let it go limp. Recorded even when the close raised (its error is the
        caller's to say): a release sent before the failure still happened.

        A close that failed after the park was read back takes the "parked" back: the
        emulated arm's elevation servo, overloaded at the close's read, went limp and the arm
        fell from the park pose, while the run said, and the manifest kept, "the arm parked"
        beside the fault."""
        try:
            self.carrier.close()
        except Exception:
            if self.end is not None and self.end.outcome == "parked":
                self.end = replace(
                    self.end,
                    outcome="park-unconfirmed",
                    why=(
                        "its close failed after the park was read back: a joint may have "
                        "gone limp since and let the arm sag from the park pose"
                    ),
                )
            raise
        finally:
            self._record_release()

    def _record_release(self) -> None:
        carrier = self.read_back
        if carrier is None or self.end is None:
            return
        # what the close established of the torque, whatever it did (kept on away from the
        # park pose had been in no record: read the same as "released nothing")
        at_close = carrier.torque_at_close()
        if at_close is not None:
            self.end = replace(self.end, torque_at_close=at_close.to_dict())
        said = carrier.torque_release_note()
        if not said:
            return
        why = self.end.why
        if self.stopped_by is not None:  # "torque on" no longer true: the close released it
            why = self._stopped_why(released=True)
        self.end = replace(self.end, why=why, torque=str(said))

    def problem(self, step: LightStep) -> str | None:
        return self.carrier.unreachable_reason(np.asarray(step.direction))

    def set(self, step: LightStep) -> ActualLight:
        try:
            reached = self.carrier.move_to(np.asarray(step.direction))
            self.carrier.lamp(True)
        except Exception as exc:  # the arm's own failure: remembered so that it is not parked
            self.arm_failure = exc
            raise
        return ActualLight((float(reached[0]), float(reached[1]), float(reached[2])))

    def off(self) -> None:
        self.carrier.lamp(False)

    def check_held(self) -> None:
        """After a capture: raise unless the arm still holds the direction it reached, with
        no servo fault (a carrier that cannot tell does nothing). The image is then not kept:
        a servo that overloaded during the exposure went limp and the arm may have sagged,
        and the image had been kept under the direction read before it."""
        carrier = self.read_back
        if carrier is None:
            return
        try:
            carrier.check_held()
        except Exception as exc:  # the arm's own failure: no park after it
            self.arm_failure = exc
            raise

    @property
    def link_open(self) -> bool:
        """Always False: an arm's safe state (lamp off, stop, the park its policy asks for) is
        the controller's teardown's and the carrier's close's, never sent from a session's
        close on its own (a park is a move): the getattr this replaced answered False too.

        A session closed before its teardown ran still switches the lamp off: its close calls
        :meth:`close`, and the carrier's close sends the lamp-off and the stop while it is
        connected (an arm stopped as the teardown began had its lit lamp switched off there:
        tests/cli/test_run_cut_end_recorded.py)."""
        return False

    def safe(self, emergency: bool = False) -> list[str]:
        """Lamp off, stop, then park as the policy says; :attr:`end` records where the arm
        was left, as read back (see :mod:`rti_rig.runtime.arm_end`).

        Ctrl-C and SIGTERM are held here (as by the caller's own hold, which delivers them
        once the teardown is done), but one that comes before or during the park stops it:
        the arm is held where it stands, torque on (:attr:`stopped_by` names the signal).
        Why: the park is a move of up to ``move_timeout_s``, and a user's stop sat it out.
        :attr:`stopped_by` is set only of a park the signal stopped or kept from starting: one
        held during a teardown with no park due, or after the park had ended, stopped none,
        and the run had then said "Stopped during the arm's park" of an arm left or parked."""
        self.stopped_by = None
        self._stop_asked = None
        self.not_sent = ()
        self.unheld = ()

        def stop_asked(signum: int) -> None:
            if self._stop_asked is None:
                self._stop_asked = signum

        with signals_deferred(on_held=stop_asked):
            return self._safe(emergency)

    def _stopped_why(self, released: bool = False) -> str:
        """Why the arm is where the stop left it; ``released``: the close then found it at the
        park pose and released its torque (said after this, from the carrier's own note)."""
        who = stop_words(signal.Signals(self.stopped_by or signal.SIGTERM))
        if released:
            return (
                f"the park was stopped by {who}: held where it stopped, close enough to the park "
                "pose for the close to release it"
            )
        return f"the park was stopped by {who}: held where it stopped, torque on"

    def _safe(self, emergency: bool) -> list[str]:
        self.park_s, self.park_finished = None, False
        lamp_failed = attempt_all([("lamp off", lambda: self.carrier.lamp(False))])
        unheld: list[UnheldJoint] = []
        stop_failed = attempt_all([("stop", lambda: stop_reading_unheld(self.carrier, unheld))])
        self.unheld = tuple(unheld)
        failures = lamp_failed + stop_failed
        self.not_sent = tuple(
            label for label, failed in (("lamp off", lamp_failed), ("stop", stop_failed)) if failed
        )
        if self.connect_failed:
            # a connect that failed (a servo reporting an overload as the port opened): no
            # park, and no end to record, as nothing was read back; what may be said of the
            # servos is the carrier's (``not_connected_sentence``). A park had been asked of it,
            # refused by its driver and reported as a teardown problem ("park: not connected;
            # call connect() first") of a move that must not be tried
            self.end = None
            return failures
        if not (self.park_on_emergency if emergency else self.park_after_session):
            policy = (
                "park_on_emergency_stop is off: an emergency stop leaves it where it stopped"
                if emergency
                else "park_after_session is off"
            )
            # a stop that did not hold may leave the arm moving: its position is not read as
            # where it is left (a silent servo would also spend its timeouts on the read)
            self.end = (
                ArmEnd(
                    "left",
                    None,
                    None,
                    f"{policy}; the stop failed (above), so it may still be moving",
                )
                if stop_failed
                else left_end(self.carrier, policy)
            )
            return failures
        if self.arm_failure is not None or stop_failed:
            why = "own move failed" if self.arm_failure is not None else "stop failed"
            # "left where it stopped" only of a stop that held every joint: one that did not
            # answer may still be moving to its last goal (the stop's failure above says so)
            left = (
                "it was left as the failed stop above describes, not moved again"
                if stop_failed
                else "it was left where it stopped"
            )
            # what to do, in the order it is done: after a failed stop the power goes off
            # first (as the stop's error and the lights line say); "park it with rti-rig
            # check" had followed "switch the power off" with no word of the power coming back
            check = park_check(self.config)
            todo = (
                "Support the lamp and switch the arm's power off first (a joint the stop did "
                "not hold may still be moving, or sag); then clear the fault (its error says "
                f"how), switch the power back on and park it with {check}"
                if stop_failed
                else f"Clear the fault (its error says how), then park it with {check}"
            )
            # said once, as where the arm was left: it had also been listed as a teardown
            # failure ("park: not attempted because …"), and the arm's sentence repeated it
            self.end = ArmEnd(
                "park-unconfirmed",
                None,
                None,
                f"not attempted because the arm's {why}: parking is a move of both joints, and "
                f"a faulty or blocked arm must not be driven near the object; {left}. {todo}",
            )
            return failures
        if self._stop_asked is not None:  # a stop came as the lamp went off: no park begun
            self.stopped_by = self._stop_asked
            self.end = left_end(self.carrier, self._stopped_why())
            return failures
        began = self.clock.now() if self.clock is not None else None
        try:
            self.carrier.park(cancelled=lambda: self._stop_asked is not None)
        except MoveCancelled:  # held where it stood, every joint (the driver's stop)
            self.stopped_by = self._stop_asked
            self.end = left_end(self.carrier, self._stopped_why())
            return failures
        except Exception as exc:  # teardown must go on whatever the arm does
            parked = [f"park: {exc}"]
            self.end = park_end(self.carrier, parked[0])
            return failures + parked
        finally:
            if began is not None and self.clock is not None:
                self.park_s = self.clock.now() - began
        self.park_finished = True
        self.end = park_end(self.carrier, None)
        return failures


#: The label of a teardown failure that is the lights' port not closing cleanly, as the
#: manifest's ``teardown_failures`` records it (``"port close: …"``, the shape of every teardown
#: failure, which readers of older sessions know).
PORT_CLOSE = "port close"


class PortCloseFailure(str):
    """A teardown failure that is the lights' port not closing cleanly (its words said to the
    user as it happened): recorded among the run's ``teardown_failures`` as its text, like
    every teardown failure, but no sign that the lights are unsafe, as the all-off before it
    says what it established.

    Why a type: :func:`unsafe_failures` had told it from an all-off's failure by its text's
    prefix, so a change of wording (or another failure worded alike) could have changed what
    the run calls safe. A ``str`` so that every list of teardown failures, and the manifest's
    JSON, holds it as it held its text."""

    __slots__ = ()

    @classmethod
    def said(cls, words: str) -> PortCloseFailure:
        """The record of a close said in ``words`` (``"port close: <words>"``)."""
        return cls(f"{PORT_CLOSE}: {words}")


def port_close_failures(lighting: Lighting) -> list[str]:
    """The run's record of the lights' last close failing to release their port (one
    :class:`PortCloseFailure`), none when it closed cleanly.

    Why: a dome's close never raises its port's failure (it must not mask the error that led
    to the close), so the teardown's ``try`` around the close never saw it: the user was told,
    the manifest's and journal's ``teardown_failures`` said nothing went wrong."""
    said = lighting.port_close_failure()
    return [] if said is None else [PortCloseFailure.said(said)]


def unsafe_failures(failures: Iterable[str] | None) -> list[str]:
    """The teardown failures that leave the lights' safe state in doubt: each but a
    :class:`PortCloseFailure` (said as it happened, and coming after the all-off that says
    what it established). Told by type, never by wording: a plain text that reads like a port's
    close is kept as unsafe."""
    return [f for f in failures or () if not isinstance(f, PortCloseFailure)]


def stop_reading_unheld(carrier: LightCarrier, unheld: list[UnheldJoint]) -> None:
    """``carrier.stop()``; a stop that did not hold every joint adds to ``unheld`` what was
    read of each joint it did not hold, then raises on (for :func:`attempt_all`)."""
    try:
        carrier.stop()
    except StopIncomplete as exc:
        unheld.extend(exc.unheld)
        raise


def attempt_all(actions: list[tuple[str, object]]) -> list[str]:
    """Run every teardown action even if some fail; return the failures as text."""
    failures = []
    for label, action in actions:
        try:
            action()  # type: ignore[operator]
        except Exception as exc:  # teardown must go on whatever one device does
            failures.append(f"{label}: {exc}")
    return failures
