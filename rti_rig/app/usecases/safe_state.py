"""What a user is told about the lights after a session or check ended early.

Never "lights are off" unless that was established: a dome reports the outcome of its last
all-off (acknowledged, sent to a firmware that never acknowledges, sent but unconfirmed, not
sent), an arm that its lamp-off was requested — or, for a real arm whose lamp is not on the
servo bus (``lamp = "software"``), that nothing switched it.
"""

from __future__ import annotations

from rti_rig.core.devices import KnownStateLightSource
from rti_rig.core.dome_link import OffOutcome
from rti_rig.core.errors import RtiRigError, UnheldJoint
from rti_rig.runtime.arm_check import not_connected_sentence
from rti_rig.runtime.arm_end import ArmEnd
from rti_rig.runtime.controller import EmergencyStop
from rti_rig.runtime.dome_policy import lights_state_sentence
from rti_rig.runtime.flash_sync import CameraTriggeredLighting
from rti_rig.runtime.lighting import ArmLighting, DomeLighting


def carry_lights_state(exc: BaseException, state: str) -> None:
    """Attach to ``exc``, the error or stop that ended metering, what metering's teardown
    established of the lights (:func:`lights_state`), for the CLI to say before the error.

    :class:`~rti_rig.core.errors.RtiRigError` and
    :class:`~rti_rig.runtime.controller.EmergencyStop` declare ``lights_state`` and are read
    plainly; a Ctrl-C's KeyboardInterrupt or a camera driver's TypeError is raised on as it
    is (wrapped, it would be said and stop otherwise) and its type cannot declare it: this
    and :func:`lights_state_of` alone spell the name for those."""
    exc.lights_state = state  # type: ignore[attr-defined]  # declared where the type can


def lights_state_of(exc: BaseException) -> str | None:
    """What :func:`carry_lights_state` attached to ``exc`` (None: ``exc`` did not end
    metering, or the lights' state could not be told)."""
    if isinstance(exc, (RtiRigError, EmergencyStop)):
        return exc.lights_state
    state = getattr(exc, "lights_state", None)
    return state if isinstance(state, str) else None


def software_lamp(lighting: object) -> bool:
    """Whether ``lighting`` is an arm whose lamp no command of rti-rig reaches (``lamp =
    "software"`` on a Dynamixel arm: its switch is outside the servo bus).

    Asked of the arm's declared type (:class:`~rti_rig.core.devices.ReadBackCarrier`, whose
    ``lamp_servo`` is None for such a lamp), where a ``getattr`` chain on ``settings.lamp`` had
    answered "not software" for any carrier that renamed or lacked it. A simulated arm
    declares no read-back: its lamp is the simulation's, switched."""
    read_back = lighting.read_back if isinstance(lighting, ArmLighting) else None
    return read_back is not None and read_back.lamp_servo() is None


def lights_state(  # type: ignore[no-untyped-def]
    rig,
    teardown_failed: bool = False,
    *,
    end: ArmEnd | None = None,
    not_sent: tuple[str, ...] | None = None,
    unheld: tuple[UnheldJoint, ...] | None = None,
) -> str:
    """One sentence on the lights of ``rig`` after its teardown (``teardown_failed``: the
    teardown's failures were printed just before, and the sentence points at them; ``end`` and
    ``not_sent``: where a teardown other than the session's left an arm, as read back, and
    which of its lamp-off and stop failed, and ``unheld`` what was read of each joint that
    stop did not hold — a stopped check's self-test, whose record the rig's lighting does not
    hold; None: the lighting's own)."""
    lighting = rig.lighting
    if getattr(rig.loaded.config, "backend", None) == "replay":
        return "a replayed acquisition has no lights to switch off"
    if isinstance(lighting, CameraTriggeredLighting):  # it knows best what it can say
        return lighting.lights_state()
    if isinstance(lighting, DomeLighting):
        policy = lighting.policy  # asked by type: a dome on a port keeps its all-off's outcome
        if policy is not None:
            return lights_state_sentence(policy)
        known = lighting.known_state
        if known is not None:  # a simulated dome: what it was sent, which it keeps exactly
            return simulated_lights_sentence(known)
        # a source that keeps no record of its all-off: the teardown sent one all the same
        # (it had been said "no all-off was attempted", of a dome the controller had sent one)
        return "whether the dome's lights are off is not known: check them"
    carrier = lighting.carrier if isinstance(lighting, ArmLighting) else None
    unreached = not_connected_sentence(carrier)
    if unreached is not None:
        return unreached
    after = " (see the teardown problems above)" if teardown_failed else ""
    if not_sent is None:
        not_sent = lighting.not_sent if isinstance(lighting, ArmLighting) else ()
    software = software_lamp(lighting) and getattr(rig.loaded.config, "backend", None) == "hardware"
    if unheld is None:
        unheld = lighting.unheld if isinstance(lighting, ArmLighting) else ()
    if not_sent:
        said = not_sent_sentence(not_sent, software, unheld)
    elif software:
        # the lamp's own switch is outside the servo bus: its "off" is a flag in the driver,
        # and "lamp off ... requested" had told a user at a real arm that it was switched
        said = (
            'stop was requested; the lamp is not switched by rti-rig (lamp = "software" in '
            "[arm.dynamixel]: its switch is outside the servo bus), so switch it off yourself"
        )
    else:
        said = "lamp off and stop were requested"
    # where the arm was left, as read back at the teardown (it had gone unsaid: "lamp off and
    # stop were requested" after a park, after no park, and after a park that failed alike)
    if end is None and isinstance(lighting, ArmLighting):
        end = lighting.end
    if end is not None:
        said += f"; {end.sentence()}"
    return said + after


#: What a failed teardown write establishes: the failure is any exception (a port gone before
#: the write, or a status reply that never came after it), so not that the request never left.
_UNSURE = "(not sent, or sent and not acknowledged)"


def not_sent_sentence(
    not_sent: tuple[str, ...], software_lamp: bool = False, unheld: tuple[UnheldJoint, ...] = ()
) -> str:
    """What is known of an arm whose teardown lamp-off or stop failed (its port gone: an
    unplugged adapter; or a servo that did not answer), said in place of "lamp off
    and stop were requested", which had been printed of requests that never left the computer.

    A Dynamixel servo no host reaches keeps the last goal it was sent, under torque, so the arm
    may hold there or still be moving to it; the lamp keeps its last state. Only removing the
    arm's power settles both.

    rti-rig sets no Bus Watchdog (address 98), and one would not settle them. The ROBOTIS
    e-manual's X-series control table ("Bus Watchdog(98)", e.g.
    https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/, from ROBOTIS-GIT/emanual
    ``_includes/en/dxl/control_table_buswatchdog.md``) has it watch the time between
    instruction packets whenever Torque Enable is 1 and limits it to no operating mode (Goal
    Position is among the goals its error makes read-only; its one example is in velocity
    mode): past 1..127 x 20 ms without a packet "the DYNAMIXEL will stop". In position mode
    that stops a move short of its goal, torque still on: the arm holds where it stopped
    instead of at a goal that was a pose checked safe before it was sent, and neither torque
    nor the lamp goes off. Setting it would also have a session send a packet at least every
    2.54 s through each exposure and wait, or find its servos stopped and their goals refused
    (Data Range Error) until the error is cleared. With or without it the servo stays under
    torque, which is why the sentence says to switch the arm's power off.

    Unless the servo shut itself off: a stop that failed because a servo reported a hardware
    fault its Shutdown register selects (an overload, on an XL430) met a servo whose torque
    is off, its joint limp, and the arm may sag. ``unheld`` (what the stop read of each joint
    it did not hold) says which: torque read off, read on, or not read (then both are said).
    Why: "keeps its last goal under torque" had been said after an overload that had switched
    the torque off. A stop whose failure read nothing of a fault (a servo that did not answer,
    a port gone) is said as before."""
    lamp_unsent = "lamp off" in not_sent
    stop_unsent = "stop" in not_sent
    if lamp_unsent and stop_unsent:
        said = f"the lamp-off and the stop failed {_UNSURE}"
    elif stop_unsent:
        said = f"the stop failed at a servo {_UNSURE}"
        if not software_lamp:
            said = "lamp off was requested, but " + said
    else:
        said = f"stop was requested, but the lamp-off failed {_UNSURE}"
    known = []
    if lamp_unsent:
        known.append("the lamp may still be lit")
    may_sag = False
    if stop_unsent:
        faulted = [j for j in unheld if j.fault]
        for joint in faulted:
            known.append(_faulted_joint_said(joint))
            may_sag = may_sag or (joint.torque_on is not True and _bears_weight(joint))
        silent = [j for j in unheld if not j.fault and j.no_reply]
        if silent:
            known.append(_silent_joints_said(silent))
            may_sag = may_sag or any(_bears_weight(j) for j in silent)
        if not (faulted or silent) or any(not (j.fault or j.no_reply) for j in unheld):
            known.append(
                "a servo no command reaches keeps its last goal under torque, so the arm may "
                "hold there or still be moving to it"
            )
    power_off = (
        "support the arm and switch its power supply off"
        if may_sag
        else "switch the arm's power supply off"
    )
    if stop_unsent and any(j.no_reply for j in unheld):
        power_off = "look at the arm before touching it, " + power_off
    said += ": " + ", and ".join(known) + "; " + power_off
    if software_lamp:
        said += (
            ' (the lamp is not switched by rti-rig: lamp = "software" in [arm.dynamixel], '
            "so switch it off yourself too)"
        )
    return said


def _silent_joints_said(joints: list[UnheldJoint]) -> str:
    """What is known of servos that gave no reply to the stop: nothing. Why: "a servo no command
    reaches keeps its last goal under torque" had been said beside an error blaming a lost
    power supply, of servos that, unpowered, are limp (the arm free to sag)."""
    servos = " and ".join(f"the {j.joint} servo (id {j.servo_id})" for j in joints)
    verb, them = ("gives", "it") if len(joints) == 1 else ("give", "them")
    # a limp azimuth lets the arm turn about the vertical; a joint the arm hangs on, sag
    limp = (
        "the arm may sag"
        if any(_bears_weight(j) for j in joints)
        else "the arm turns freely about the vertical if pushed"
    )
    return (
        f"{servos} {verb} no reply, so nothing is known of {them}: unpowered, a servo is limp and "
        f"{limp}; powered, it keeps its last goal under torque, and the arm may hold "
        "there or still be moving to it"
    )


def _bears_weight(joint: UnheldJoint) -> bool:
    """Whether the arm hangs on ``joint``: every joint but the azimuth, which turns about the
    vertical (a limp one lets the arm swing round if pushed, not sag)."""
    return joint.joint != "azimuth"


def _limp_said(joint: UnheldJoint) -> str:
    """What a limp ``joint`` lets the arm do. Why: "that joint is limp, so the arm may sag" had
    been said of the azimuth servo, sending an operator to hold up an arm that the limp joint
    lets turn, not fall (QA, 2026-12-05)."""
    if _bears_weight(joint):
        return "so the arm may sag"
    return "so the arm turns freely about the vertical if pushed"


def _faulted_joint_said(joint: UnheldJoint) -> str:
    """What a servo that reported a fault as the stop read it was left doing, as read."""
    servo = f"the {joint.joint} servo (id {joint.servo_id})"
    if joint.torque_on is False:
        return (
            f"{servo} shut itself off after its fault (torque read off): that joint is limp, "
            f"{_limp_said(joint)}"
        )
    if joint.torque_on is True:
        return (
            f"{servo} kept its torque after its fault (read on): it keeps its last goal, so the "
            "arm may hold there or still be moving to it"
        )
    return (
        f"{servo} reported a fault and its torque could not be read: it may have shut itself "
        f"off (that joint limp, {_limp_said(joint)}) or keep its last goal under torque (so "
        "the arm may hold there or still be moving to it)"
    )


def simulated_lights_sentence(known: KnownStateLightSource) -> str:
    """What a dome whose state is known exactly (a simulated one) was left with: "switched
    off" only when an all-off reached it after its last light (it had been said of every
    simulated dome, also of one a session closed before its teardown had left lit)."""
    lit = known.lit_now()
    if lit is not None:
        return f"LED {lit} was left lit: no all-off reached the dome after it"
    if known.switched_off():
        return "lights were switched off"
    return "nothing was lit"


def safe_state_unsure(rig) -> bool:  # type: ignore[no-untyped-def]
    """True when the rig's lights are not known to be safe after its teardown: the dome's last
    all-off was not sent or went unconfirmed (what :func:`lights_state` then tells the user to
    deal with by hand). A firmware that never acknowledges, or switches itself off, is as safe
    as it can be said to be; a simulated dome is unsure only with an LED left lit."""
    lighting = rig.lighting
    if not isinstance(lighting, DomeLighting):
        return False
    known = lighting.known_state
    if known is not None:  # a simulated dome: unsure only of an LED its commands left lit
        return known.lit_now() is not None
    policy = lighting.policy
    if policy is None:  # a source neither on a port nor known exactly: nothing established
        return True
    report = policy.off_report
    if report is None:
        return True  # a real dome that sent no all-off
    return report.outcome in (
        OffOutcome.SENT_UNCONFIRMED,
        OffOutcome.NOT_SENT,
        OffOutcome.NEVER_OPENED,
    )
