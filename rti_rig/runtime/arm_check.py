"""Self-test of a light-carrying arm: connect, visit a few poses that span its band, park.

What a user wants to know before trusting an arm with an object under it: does every joint
answer, does the arm reach where it is told (within ``tolerance_deg``) across its whole band —
lowest and highest reachable elevations, both ends of its azimuth range — does the lamp switch,
and how long does a move take. Every pose is checked against the arm's limits and keep-out cone
*before* it is sent; the lamp is switched off and the arm stopped whatever happens, and it
parks at the end unless the test was aborted by a device error (moving a faulty arm near an
object is what the abort protects against; the same rule as an emergency stop).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.clock import Clock
from rti_rig.core.device_said import first_clause
from rti_rig.core.devices import LightCarrier, ReadBackCarrier
from rti_rig.core.errors import RtiRigError, UnheldJoint
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction, direction_from_az_el
from rti_rig.core.rig_geometry import ArmGeometry
from rti_rig.runtime.arm_end import PARK_TOLERANCE_DEG, ArmEnd, left_end, park_end
from rti_rig.runtime.controller import EmergencyStop
from rti_rig.runtime.lighting import attempt_all, stop_reading_unheld
from rti_rig.runtime.teardown_repeats import failed_as_before

#: Largest angle between the asked and the reached direction that passes (degrees).
TOLERANCE_DEG = 1.0


def arm_label(name: str) -> str:
    """How the check's heading names the arm: its own name when that already says "arm" (the
    driver's default name is ``arm``, the simulator's ``simulated arm``), else "arm NAME".

    Why: the heading was always "arm NAME", which read "arm arm: 8 poses" on the shipped
    configs; a name such as ``tablet-rig`` still needs the noun to say what was checked.
    """
    return name if "arm" in re.split(r"[^a-z]+", name.lower()) else f"arm {name}"


@dataclass(frozen=True)
class PoseCheck:
    """One visited pose: asked and reached (azimuth, elevation), the error and the move time."""

    label: str
    asked_az_el: tuple[float, float]
    reached_az_el: tuple[float, float] | None
    error_deg: float | None
    move_s: float | None
    ok: bool
    message: str = ""


@dataclass
class ArmSelfTestReport:
    """What the arm self-test saw, for the CLI to print."""

    name: str
    tolerance_deg: float
    park_wanted: bool = True
    checks: list[PoseCheck] = field(default_factory=list)
    #: how many poses the walk was to visit (:func:`self_test_poses`)
    planned: int = 0
    #: the park was commanded and returned (not yet that it is where it was sent: see ``end``)
    parked: bool = False
    aborted: str | None = None
    #: the walk was ended by a stop (Ctrl-C, SIGTERM), not by an error: a stopped check does
    #: not park, by the user's choice (decided on here, not on how ``aborted`` begins)
    stopped_by_user: bool = False
    #: the stop's own words ("Ctrl-C"), as a move it cut short recorded them
    stop: str | None = None
    teardown_failures: list[str] = field(default_factory=list)
    elapsed_s: float = 0.0
    #: what may be said of an arm whose connect failed (:func:`not_connected_sentence`)
    not_connected: str | None = None
    #: whether the teardown's stop succeeded (every joint held): only then is the arm said to
    #: have been stopped
    stopped: bool = True
    #: the device's own words of the error that aborted the walk (its fault and what to do),
    #: said in full once, under ABORTED: the failed pose's row and a teardown that met the
    #: same fault point back to it (one overload's paragraph had been printed three times)
    aborted_detail: str | None = None
    #: where the teardown left the arm, as read back after its stop (None: it never connected,
    #: so nothing was moved); "parked" only of a park read back at the park pose. Its
    #: ``torque`` is what the close then did to the joints' torque (released, by its policy),
    #: the one record of it that the park line and a stopped check's end sentence both say
    end: ArmEnd | None = None
    #: the servo whose LED the lamp hangs on (None: no command reaches the lamp), and at how
    #: many poses its on and its off were both answered: the check flashed a servo LED and
    #: had never said so, nor that the servo took the writes
    lamp_servo: int | None = None
    lamp_flashes: int = 0
    #: which of the teardown's "lamp off" and "stop" failed (not sent, or not acknowledged):
    #: a stopped check's lights line says what that leaves (:func:`not_sent_sentence`), as
    #: ``run``'s does from ``ArmLighting.not_sent``; it had said "lamp off and stop were
    #: requested" of a lamp-off that had failed
    not_sent: tuple[str, ...] = ()
    #: the joints the teardown's failed stop did not hold, as read (its servo's fault and the
    #: torque read after it), for the same lights line
    unheld: tuple[UnheldJoint, ...] = ()

    @property
    def park_confirmed(self) -> bool:
        """The park returned and was read back at the park pose."""
        return self.parked and self.end is not None and self.end.outcome == "parked"

    @property
    def ok(self) -> bool:
        return (
            self.aborted is None
            and not self.teardown_failures
            and bool(self.checks)
            and all(c.ok for c in self.checks)
            and (self.park_confirmed if self.park_wanted else not self.parked)
        )

    def stopped_lines(self) -> list[str]:
        """What a walk stopped by the user (Ctrl-C, SIGTERM) had verified: its heading, the
        poses visited (the one under way when the stop came said as not verified), their move
        times and the lamp's flashes; where the arm was left is said by the stop's own line.

        Why: a stopped check printed none of the poses it had already verified, only that it
        had stopped: a user who stopped it at pose 6 of 8 could not tell what had passed."""
        return self._walk_lines()

    def _walk_lines(self) -> list[str]:
        # the heading says how far the walk got: "arm: 3 poses" had been printed of a walk
        # stopped at pose 3 of 8, and "arm: 0 poses" with an empty table of one never started
        label, done = arm_label(self.name), len(self.checks)
        verified = sum(c.ok for c in self.checks)
        if self.stopped_by_user and not done:
            out = [f"{label}: {self.aborted} before its first pose: no pose verified"]
        elif self.stopped_by_user:
            out = [
                f"{label}: {self.aborted} at pose {done} of {self.planned}; "
                f"{verified} verified within {self.tolerance_deg:g}°"
            ]
        elif not done:
            out = [f"{label}: no pose visited (see ABORTED below)"]
        elif done < self.planned:
            out = [
                f"{label}: stopped at pose {done} of {self.planned}, "
                f"tolerance {self.tolerance_deg:g}°"
            ]
        else:
            out = [f"{label}: {done} poses, tolerance {self.tolerance_deg:g}°"]
        if done:
            out.append("  pose               asked az/el       reached az/el     error   move")
        for c in self.checks:
            az, el = c.asked_az_el
            if c.reached_az_el is None and self.stopped_by_user and c.message == self.stop:
                # the move the stop cut short: not a failure of the arm
                out.append(
                    f"  {c.label:18s} {az:7.2f}°/{el:5.2f}°  not verified: {self.aborted} "
                    "during this move"
                )
                continue
            if c.reached_az_el is None:
                said = "see ABORTED below" if c.message == self.aborted else c.message
                out.append(f"  {c.label:18s} {az:7.2f}°/{el:5.2f}°  FAIL {said}")
                continue
            raz, rel = c.reached_az_el
            verdict = "ok" if c.ok else f"FAIL {c.message}"
            out.append(
                f"  {c.label:18s} {az:7.2f}°/{el:5.2f}° → {raz:7.2f}°/{rel:5.2f}°  "
                f"{c.error_deg:.3f}°  {c.move_s:5.2f} s  {verdict}"
            )
        moves = [c.move_s for c in self.checks if c.move_s is not None]
        if moves:
            out.append(f"move time: median {np.median(moves):.2f} s, longest {max(moves):.2f} s")
        if self.lamp_servo is not None and self.lamp_flashes:
            poses = "each pose" if self.lamp_flashes == done else f"{self.lamp_flashes} pose(s)"
            out.append(
                f"lamp: flashed at {poses} on servo {self.lamp_servo}'s LED, on and off each "
                "answered by the servo"
            )
        return out

    def lines(self) -> list[str]:
        out = self._walk_lines()
        if self.aborted and self.not_connected:
            # no stop or hold to speak of (it had said "stopped where it was" of an arm whose
            # port could not even be opened)
            out.append(f"ABORTED: {self.aborted} ({self.not_connected})")
        elif self.aborted:
            # where it was left, and whether the stop held, is said once, on the park line
            # below: it had been said here too ("not parked: the arm was stopped where it was",
            # "not parked; the stop did not hold every joint"), then again as "NOT parked"
            out.append(
                f"ABORTED: {self.aborted}"
                + (" (see the teardown below)" if self.teardown_failures else "")
            )
        out.extend(f"teardown FAILED: {self._said_once(f)}" for f in self.teardown_failures)
        out.append(self._park_line())
        out.append(f"elapsed {self.elapsed_s:.1f} s on the rig's clock")
        out.append("RESULT: " + ("PASS" if self.ok else "FAIL"))
        return out

    def _park_line(self) -> str:
        """Where the arm was left, as read back after the teardown's stop: "parked" only of a
        park read back within :data:`PARK_TOLERANCE_DEG` of the park pose.

        Why: the check said "parked" of any park that returned, without reading where the arm
        was, and of a check stopped early (an error, Ctrl-C) said "NOT parked" and nothing of
        where the arm had been left, which ``run`` says (``runner.arm_end``)."""
        end = self.end
        policy = "" if self.park_wanted else " (park_after_session is off)"
        if end is None:  # never connected: nothing moved (ABORTED says why)
            return "NOT parked" + policy
        at = (
            f"az {end.azimuth_deg:.1f}°, el {end.elevation_deg:.1f}°"
            if end.azimuth_deg is not None and end.elevation_deg is not None
            else None
        )
        # what the close then did to the torque, wherever the arm was left: a close releases
        # an arm it finds at its park pose also when the park was not confirmed (off by
        # policy, stopped, failed), and that release had gone unsaid
        released = f"; {end.torque}" if end.torque else ""
        if self.park_confirmed:
            return (
                f"parked (read back at {at}, within {PARK_TOLERANCE_DEG:g}° of its park pose)"
                + released
            )
        head = "park NOT confirmed" if self.parked else "NOT parked"
        why = self._said_once(end.why) if end.why else ""
        if not self.park_wanted:  # "NOT parked (park_after_session is off…)", as before
            said = f"{head} ({why})" if why else head + policy
        else:
            said = f"{head}: {why}" if why else head
        return said + (f"; left at {at} (read back)" if at else "") + released

    def _said_once(self, text: str) -> str:
        """``text`` with the aborting error's explanation, said in full under ABORTED,
        shortened to its first clause (the fault itself) and a pointer back."""
        return said_once(text, self.aborted_detail, "as under ABORTED above")


def said_once(text: str, detail: str | None, pointer: str) -> str:
    """``text`` with ``detail`` (an error's explanation, said in full elsewhere) shortened to
    its first clause (the fault itself) and ``(pointer)``: a servo fault's paragraph of what to
    do is said once, not again by every teardown step that met the same fault. The first
    clause ends at a ``;`` outside parentheses: one inside a quoted system error (a lost port's
    "No such file or directory; serial ports present now: …") had cut the head there, its
    parenthesis left open."""
    if not detail or len(detail) < 60 or detail not in text:
        return text
    return text.replace(detail, f"{first_clause(detail)} ({pointer})")


def not_connected_sentence(carrier: object, connected: bool | None = None) -> str | None:
    """What may truthfully be said of an arm whose connect never completed (None: it did;
    ``connected``: known by the caller, else the carrier's ``ever_connected``). Nothing was
    commanded if nothing was ever written to a servo; nothing driven if only torque-off and
    EEPROM writes went out (:attr:`DynamixelArm.driven`); a connect that failed after another
    write (profiles, a goal, torque on) may have left a servo holding under torque.

    Asked of the carrier's declared type (:class:`ReadBackCarrier`), where ``getattr`` had
    answered "connected" for a misspelt name; a carrier that declares none (the simulated
    arm, connected in process) is taken as connected unless the caller knows otherwise, and
    then as commanded and driven: nothing less may be said of it."""
    read_back = carrier if isinstance(carrier, ReadBackCarrier) else None
    if connected is None:
        connected = read_back is None or read_back.ever_connected
    if connected:
        return None
    # what the failed connect read of the torque before it let the port go: an arm an
    # earlier command left holding still holds (its RAM kept while powered), and "nothing
    # was commanded … NOT parked" had been all a user reaching in to fix the fault was told
    found = read_back.holding_after_failed_connect() if read_back is not None else None
    tail = f"; {found}" if found else ""
    if read_back is not None and not read_back.commanded:
        return "nothing was commanded: the arm could not be connected" + tail
    if read_back is not None and not read_back.driven:
        # only torque-off and EEPROM writes went out (the position limits a first connect
        # writes): "a servo may be holding under torque" had been said beside a refusal that
        # had just read every servo's torque off
        return (
            "the arm could not be connected; rti-rig switched no servo's torque on (it only "
            "switched torque off to write servo settings)" + tail
        )
    return (
        "the arm's connection failed part-way, after settings were written to its servos: a "
        "servo may be holding its position under torque; switch the arm's power off before "
        "touching it"
    )


def self_test_poses(geometry: ArmGeometry) -> list[tuple[str, NDArray[np.float64]]]:
    """Poses spanning the arm's band: both elevation extremes, the azimuth range's ends, middle.

    Kept 0.5° inside every limit, so that a correct arm is never asked for a pose on the edge of
    what its own limit checks accept.
    """
    lo, hi = geometry.elevation_band(0.0)
    lo, hi = lo + 0.5, hi - 0.5
    mid = 0.5 * (lo + hi)
    # both ends of the azimuth range (on a full turn: either side of the cable stop) and between
    azimuths = list(np.linspace(geometry.min_azimuth_deg + 0.5, geometry.max_azimuth_deg - 0.5, 4))
    poses = [(f"low, az {a:.0f}°", direction_from_az_el(a, lo)) for a in azimuths[::2]]
    poses += [(f"high, az {a:.0f}°", direction_from_az_el(a, hi)) for a in azimuths[1::2]]
    poses += [(f"middle, az {a:.0f}°", direction_from_az_el(a, mid)) for a in azimuths]
    return poses


def _az_el(direction: NDArray[np.float64]) -> tuple[float, float]:
    az, el = az_el_from_direction(np.asarray(direction, dtype=np.float64))
    a = float(az) - 360.0 if float(az) > 180.0 else float(az)
    return a, float(el)


def arm_self_test(
    carrier: LightCarrier,
    geometry: ArmGeometry,
    clock: Clock,
    *,
    tolerance_deg: float = TOLERANCE_DEG,
    lamp_s: float = 0.05,
    park: bool = True,
) -> ArmSelfTestReport:
    """Connect, visit :func:`self_test_poses` (lamp flashed at each), park (unless ``park`` is
    off: the rig's ``park_after_session`` policy), close. An error of the arm or its driver
    ends the walk and is reported, never raised; the lamp is switched off and the arm stopped in
    every case, and it is not parked after an error."""
    started = clock.now()
    report = ArmSelfTestReport(carrier.name, tolerance_deg, park_wanted=park)
    poses = self_test_poses(geometry)
    report.planned = len(poses)
    if isinstance(carrier, ReadBackCarrier):
        report.lamp_servo = carrier.lamp_servo()
    # validate every pose before anything connects or moves
    for label, d in poses:
        reason = geometry.unreachable_reason(d) or carrier.unreachable_reason(d)
        if reason:
            report.aborted = f"pose '{label}' refused before moving: {reason}"
            report.elapsed_s = clock.now() - started
            return report
    connected = False
    try:
        carrier.connect()
        connected = True
        for label, d in poses:
            t0 = clock.now()
            try:
                reached = np.asarray(carrier.move_to(d), dtype=np.float64)
            except BaseException as exc:  # a stop too: the pose it cut short is said as such
                report.checks.append(PoseCheck(label, _az_el(d), None, None, None, False, str(exc)))
                raise
            move_s = clock.now() - t0
            err = float(angle_between_deg(reached, d))
            ok = err <= tolerance_deg
            msg = "" if ok else f"reached {err:.2f}° from the asked direction"
            report.checks.append(PoseCheck(label, _az_el(d), _az_el(reached), err, move_s, ok, msg))
            carrier.lamp(True)
            clock.sleep(lamp_s)
            carrier.lamp(False)
            report.lamp_flashes += 1  # both writes returned: answered by the servo
        if park:
            carrier.park()
            report.parked = True  # returned: whether it is at the park pose is read below
    except Exception as exc:  # a self-test reports what went wrong; teardown follows
        # a device error names its device and command; anything else by its kind (the class
        # name of our own errors had been printed to the user: "CommunicationError: arm …")
        report.aborted = (
            str(exc) if isinstance(exc, RtiRigError) else f"{type(exc).__name__}: {exc}"
        )
        report.not_connected = not_connected_sentence(carrier, connected)
        report.aborted_detail = getattr(exc, "message", None)
    except BaseException as exc:  # a stop (signal): goes on up, with what the teardown found
        report.aborted = f"stopped ({exc})"
        report.stopped_by_user = True
        report.stop = str(exc)
        if isinstance(exc, EmergencyStop):  # declared there; check reads it of a stop
            exc.self_test_report = report
        raise
    finally:
        unheld: list[UnheldJoint] = []
        failures = attempt_all(
            [
                ("lamp off", lambda: carrier.lamp(False)),
                ("stop", lambda: stop_reading_unheld(carrier, unheld)),
            ]
        )
        report.unheld = tuple(unheld)
        report.stopped = not any(f.startswith("stop: ") for f in failures)
        report.not_sent = tuple(
            label
            for label in ("lamp off", "stop")
            if any(f.startswith(f"{label}: ") for f in failures)
        )
        # read back before the close releases the port (and, by its torque policy, the joints)
        report.end = _check_end(carrier, report, connected)
        failures += attempt_all([("close", carrier.close)])
        # asked by name of a carrier that reads its servos back (a rename fails there, at
        # construction); one that does not (the simulated arm) releases nothing
        released = carrier.torque_release_note() if isinstance(carrier, ReadBackCarrier) else None
        if report.end is not None and released:
            # the end a stopped check is said by (``end.sentence()``) carries the release too:
            # a check stopped with the arm at its park pose was said "not parked and left at
            # az 0.0°, el 10.0°" with no word of the torque its close had just switched off
            report.end = replace(report.end, torque=released)
        report.teardown_failures = _point_back(failures)
        report.elapsed_s = clock.now() - started
    return report


def _check_end(carrier: LightCarrier, report: ArmSelfTestReport, connected: bool) -> ArmEnd | None:
    """Where the self-test's teardown left the arm, read back after its stop (None: it never
    connected). The same record ``run`` keeps (:mod:`rti_rig.runtime.arm_end`): "parked" only
    of a park that returned and read back at the park pose; a stop that did not hold every
    joint leaves an arm that may still be moving, whose position is not read as where it is
    left (the same rule as :meth:`rti_rig.runtime.lighting.ArmLighting.safe`)."""
    if not connected:
        return None
    if report.parked:
        return park_end(carrier, None)
    stopped_by_user = report.stopped_by_user
    if not report.park_wanted:
        why = "park_after_session is off"
    elif stopped_by_user:
        why = f"the check was {report.aborted}, and a stopped check does not park"
    else:  # the ABORTED line says what ended it: parking a faulty arm is a move not made
        why = "not attempted after the error above"
    # no park by policy or by the user's stop: "left"; one the arm's error kept from being
    # attempted: not confirmed (as ``run`` records them)
    outcome = "left" if not report.park_wanted or stopped_by_user else "park-unconfirmed"
    if not report.stopped:
        return ArmEnd(
            outcome,
            None,
            None,
            f"{why}; the stop did not hold every joint (see the teardown above): its "
            "position is not read as where it is left",
        )
    end = left_end(carrier, why)
    return ArmEnd(outcome, end.azimuth_deg, end.elevation_deg, end.why)


def _point_back(failures: list[str]) -> list[str]:
    """Teardown failures, one that repeats an earlier one word for word replaced by a pointer
    to it (:func:`~rti_rig.runtime.teardown_repeats.failed_as_before`).

    Why: the driver's ``close`` stops the arm again, so one servo fault had been printed in
    full twice, a paragraph for the stop and the same paragraph for the close (``rti-rig run``
    already pointed back: :func:`rti_rig.runtime.controller._teardown_failure`)."""
    out: list[str] = []
    for failure in failures:
        label, _, text = failure.partition(": ")
        first = next((f.partition(": ")[0] for f in out if f.partition(": ")[2] == text), None)
        out.append(failed_as_before(label, first) if first is not None else failure)
    return out
