"""The servo-arm light carrier: policy for two Dynamixel X-series joints.

Safe state (``rti_rig.core.devices.LightCarrier``): lamp off, motion stopped. ``close`` restores it
as far as the hardware allows without moving the arm (parking is the caller's policy), then applies
the torque policy ("hold": servos keep holding where they are, so the arm cannot fall;
"release_on_close": torque off, but only if the arm is at the park pose).

The lamp is **tracked in software** by default (the lamp's own switch is outside the servo
bus); with ``lamp = "servo_led"`` the state is also mirrored on the LED register (65) of
``lamp_servo_id``, which is where a lamp driven from a servo board output would be wired.

Every goal a move sends goes through :meth:`DynamixelArm._send_goal`, which runs the tick-level
safety gate (:meth:`ArmKinematics.ticks_reason`) before anything reaches the bus; a stop's hold
of the present position (:meth:`DynamixelArm.stop`) is no move, and is clamped into the joints'
limits only.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.clock import Clock
from rti_rig.core.device_said import say_or_log
from rti_rig.core.devices import ReadBackCarrier, TorqueAtClose
from rti_rig.core.errors import MoveCancelled, UnheldJoint
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.core.shell_words import shell_word
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2
from rti_rig.drivers.dynamixel.bus import DxlBus, no_reply, resends_said
from rti_rig.drivers.dynamixel.faults import (
    CommunicationError,
    ConfigMismatchError,
    DynamixelError,
    HardwareFaultError,
    MoveTimeoutError,
    SafetyViolation,
    StopIncompleteError,
    UnreachableError,
)
from rti_rig.drivers.dynamixel.kinematics import (
    ArmKinematics,
    as_direction,
    clamp_ticks,
    ticks_to_joint,
)
from rti_rig.drivers.dynamixel.settings import ArmSettings

log = logging.getLogger("rti_rig.dynamixel.arm")

#: The X-series Baud Rate values (ROBOTIS e-manual, Baud Rate (8)) a silent bus is scanned at,
#: most likely first: the factory 57600, then the 1 Mbps of many older Protocol 1.0 servos and
#: of users who raise it, then the rest; 9600 last, its broadcast Ping waiting about 4.4 s.
_RATES_TO_TRY = (57600, 1_000_000, 115200, 2_000_000, 3_000_000, 4_000_000, 4_500_000, 9600)


@dataclass(frozen=True)
class RebootOutcome:
    """What :meth:`DynamixelArm.reboot_faulted` established of one joint's servo."""

    role: str
    servo_id: int
    #: Hardware Error Status as read before (0: no fault, nothing done)
    status_before: int
    rebooted: bool
    #: Hardware Error Status read back after the reboot (None: not rebooted)
    status_after: int | None = None
    #: Torque Enable as read (after the reboot; before it for one left alone)
    torque_on: bool = False
    #: how this rig's servos are power-cycled (an emulated chain's way is its own)
    power_cycle: str = ct.POWER_CYCLE

    @property
    def cleared(self) -> bool:
        """No fault is left on this servo (none was there, or the reboot cleared it)."""
        return self.status_before == 0 or (self.rebooted and self.status_after == 0)

    def sentence(self) -> str:
        who = f"servo {self.servo_id} ({self.role})"
        if not self.status_before:
            return f"{who}: no hardware fault (Hardware Error Status 0x00): not rebooted"
        # " overload" etc.; nothing for a status with only bits the e-manual names no fault
        # for (0x02): "hardware fault  (0x02)" had been said
        faults = f" {_fault_names(self.status_before)}".rstrip()
        if not self.rebooted:
            # its cause first: a power cycle alone, on the supply that faulted it (an input-
            # voltage error is the one the XL430's Shutdown leaves torque on for), faults it
            # again; the advice had been "switch the power off and on" alone
            cause = "; ".join(
                ct.FAULT_ADVICE[f] for f in ct.decode_hardware_error(self.status_before)
            )
            cause = cause or "fix the fault's cause"  # no named fault: no advice of its own
            return (
                f"{who}: hardware fault{faults} (0x{self.status_before:02X}) but its torque "
                "is on (it still holds its joint): NOT rebooted, as a reboot switches torque "
                f"off and the joint would drop; {cause}, then support the arm and "
                f"{self.power_cycle} (that clears the fault, and the joint goes limp), "
                "then run rti-rig check"
            )
        assert self.status_after is not None
        if self.status_after:
            return (
                f"{who}: hardware fault{faults} (0x{self.status_before:02X}); rebooted, but "
                f"it is still set (Hardware Error Status 0x{self.status_after:02X}): its cause "
                "remains (see the advice rti-rig check gives for it)"
            )
        return (
            f"{who}: hardware fault{faults} (0x{self.status_before:02X}); rebooted, Hardware "
            "Error Status read back 0x00, torque "
            + ("ON as read (unexpected)" if self.torque_on else "off (the joint is limp)")
        )


def _no_reply(exc: Exception) -> bool:
    """Whether ``exc`` is a servo's silence (no status within its reply window), after which
    nothing is known of it: its supply may be gone (torque off, the joint limp) as well as a
    cable, the servo still powered and holding. A corrupted reply or an error number came from
    a powered servo. Told by the bus's result code (:func:`no_reply`), as the Status Return
    Level check tells it; it had been found in the message's words."""
    return no_reply(exc)


def _fault_names(status: int) -> str:
    return ", ".join(f.name.lower().replace("_", " ") for f in ct.decode_hardware_error(status))


class DynamixelArm(ReadBackCarrier):
    """Two-axis light arm (azimuth + elevation) on Dynamixel Protocol 2.0 servos.

    ``port`` is a ``dynamixel_sdk.PortHandler`` (a real device or an emulator's pty path) or an
    in-process stand-in with the same methods; it is opened by :meth:`connect`, never here.
    """

    def __init__(
        self,
        settings: ArmSettings,
        port: Any,
        clock: Clock,
        packet_handler: Any | None = None,
        *,
        config_path: str | None = None,
        power_cycle: str = ct.POWER_CYCLE,
    ) -> None:
        self.settings = settings
        #: How this rig's servos are power-cycled, said in advice: what resets their RAM
        #: (torque, Status Return Level), which they keep between two commands while powered
        #: (an emulated chain keeps it too, in a state file whose deletion is its power cycle:
        #: :mod:`rti_rig.simulator.servo_latch`).
        self.power_cycle = power_cycle
        self.name = settings.name
        self.clock = clock
        self.kin = ArmKinematics(settings)
        # the rig config's path: a servo fault's advice names it in the command to paste
        # and how its servos are power-cycled (an emulated chain has no power switch)
        self._bus = DxlBus(
            port, settings.name, packet_handler, config=config_path, power_cycle=power_cycle
        )
        self._connected = False
        #: whether a connect ever completed (:attr:`ever_connected`)
        self._ever_connected = False
        self._lamp_on = False
        self._emergency_stopped = False
        #: ``release_on_close`` sent the torque-off at the last close (see
        #: :meth:`torque_release_note`).
        self.torque_released = False
        #: Torque Enable as read back after that torque-off: the servos still holding, and
        #: those that did not answer the read (both empty: every servo read back off).
        self._torque_after_release: tuple[list[Any], list[Any]] = ([], [])
        #: What the last close established of the torque (:meth:`torque_at_close`).
        self._torque_at_close: TorqueAtClose | None = None
        self._goal: tuple[int, int] | None = None
        #: (servo id, Hardware Error Status) of each alert a stop has said it held despite
        self._alerts_said: set[tuple[int, int]] = set()
        #: The ticks read when the last move ended in position: the pose whose direction the
        #: capture that follows is recorded under, which :meth:`check_held` compares with.
        self._reached: tuple[int, int] | None = None
        #: Where the arm says what a user must know as it happens (the command line's
        #: console, set by :meth:`listen`); None: said as a warning record, which the command
        #: line says as a note (``rti_rig.cli.app.records_as_notes``).
        self._say: Callable[[str], None] | None = None
        #: Every line said through :meth:`_tell`, in order (what the user was told).
        self.said: list[str] = []
        #: What the last failed connect read of the torque before it let the port go
        #: (:meth:`holding_after_failed_connect`); None: no connect failed since the last one
        #: that completed, or its port never opened.
        self._holding_found: str | None = None

    @property
    def ever_connected(self) -> bool:
        """Whether a connect ever completed (what a stop may say of an arm it never reached)."""
        return self._ever_connected

    @property
    def commanded(self) -> bool:
        """Whether anything was ever written to a servo (a connect writes limits, torque off,
        profiles, a goal, torque on): one that failed after its first write may have left a
        servo holding under torque, so a stop may not say that nothing was commanded."""
        return bool(self._bus.commanded)

    @property
    def driven(self) -> bool:
        """Whether anything that could leave a servo driven was ever sent (any write but a
        Torque Enable = 0 or an EEPROM write: a first connect rewrites the position limits
        that way, torque off, before it checks the pose). A connect that failed after those
        writes only left no servo driven by this driver; its stop may say so rather than
        "a servo may be holding under torque" beside a refusal that read the torque off."""
        return bool(self._bus.driven)

    # -- lifecycle --------------------------------------------------------------------------
    def connect(self) -> None:
        """Open the port, check the servos against the config, set profiles, torque on."""
        self._bus.open(self.settings.baudrate)
        try:
            for joint in self.settings.joints:  # every check on every servo, then any write
                self._check_servo(joint)
            for joint in self.settings.joints:
                if joint.mode == ct.OperatingMode.POSITION:
                    self._check_position_limits(joint)  # may write (EEPROM, torque off)
            self._check_in_limits()
            for joint in self.settings.joints:
                self._bus.write(joint.servo_id, ct.PROFILE_ACCELERATION, joint.acceleration_units)
                self._bus.write(joint.servo_id, ct.PROFILE_VELOCITY, joint.velocity_units)
            # Goal := present before torque on, so no stale goal can make the arm jump
            # (whatever the firmware does with Goal Position on torque-on).
            self._send_goal(self.joint_ticks(), "connect")
            for joint in self.settings.joints:
                self._bus.write(joint.servo_id, ct.TORQUE_ENABLE, 1)
        except BaseException as exc:
            # read-only, and not after a stop (Ctrl-C ends the connect at once)
            self._holding_found = (
                self._read_holding_after_failed_connect() if isinstance(exc, Exception) else None
            )
            self._bus.close()
            raise
        self._connected = self._ever_connected = True
        self._holding_found = None
        self.torque_released = False
        self._torque_after_release = ([], [])
        self._torque_at_close = None
        self._lamp_on = False
        self._emergency_stopped = False
        self._goal = self.joint_ticks()  # multi-turn choices start from where the arm is

    def holding_after_failed_connect(self) -> str | None:
        """What the last failed connect established of the servos' torque, as a clause for the
        user (None: no connect failed, or its port never opened: nothing could be read).

        Why: a servo keeps Torque Enable (64) while it stays powered (ROBOTIS e-manual,
        X-series control table: RAM is reset only at power-on), so an arm an earlier command
        left holding (``torque_policy = "hold"``, a crash, a check with park_after_session
        off) still holds the lamp wherever it stopped. A connect that failed before writing
        anything was said as "nothing was commanded: the arm could not be connected" and
        "NOT parked", with no word that the arm was still powered, holding the lamp away
        from its park pose: a user reaching in to fix the fault met a live arm."""
        return self._holding_found

    def _read_holding_after_failed_connect(self) -> str | None:
        """Read Torque Enable (and, of a holding arm, where it is) after a failed connect,
        read-only, before the port is let go; None if the port never opened."""
        if not getattr(self._bus.port, "is_open", False):
            return None
        on: list[Any] = []
        unread: list[Any] = []
        for joint in self.settings.joints:
            try:
                if self._bus.read(joint.servo_id, ct.TORQUE_ENABLE, check_alert=False):
                    on.append(joint)
            except Exception:  # what could not be read is said as unknown, never as off
                unread.append(joint)
        advice = (
            "support the lamp before touching the arm, and switch the arm's power off "
            f"({self.power_cycle}) or fix the fault and run the command again (its park "
            "moves the lamp to the park pose)"
        )
        if on:
            where = ""
            try:
                # with the Alert bit let through: a servo reporting a hardware fault still
                # answers with its position (read with the alert checked, the pose of an arm
                # whose elevation servo had overloaded was said "could not be read")
                ticks = tuple(
                    self._bus.read(j.servo_id, ct.PRESENT_POSITION, check_alert=False)
                    for j in self.settings.joints
                )
                az, el = self.kin.pose_of_ticks(*ticks)
                place = "at its park pose" if self._at_park(ticks) else "away from its park pose"
                where = f" at az {az:.1f}°, el {el:.1f}° (read back, {place})"
            except Exception:
                where = " (where could not be read)"
            unknown = f"; {self._servos_named(unread)} did not answer the read" if unread else ""
            # a joint read off holds nothing: "holding the lamp" had been said of an arm whose
            # elevation servo had shut down for an overload, its joint limp under the lamp
            off = [j for j in self.settings.joints if j not in on and j not in unread]
            held, limp = "holding the lamp", ""
            if off:
                held = "only partly holding the lamp"
                limp = (
                    f"; {self._servos_named(off)} read it off: that joint is limp, and the "
                    "lamp's weight may move it"
                )
            return (
                f"but the arm is still powered and {held}{where}: "
                f"{self._servos_named(on)} read Torque Enable ON (left on by an earlier "
                f"command){limp}{unknown}; {advice}"
            )
        if unread:
            answered = [j for j in self.settings.joints if j not in unread]
            off = f" ({self._servos_named(answered)} read torque off)" if answered else ""
            return (
                f"whether the arm is still holding the lamp under torque is not known: "
                f"{self._servos_named(unread)} did not answer a read of Torque Enable"
                f"{off}, and an earlier command may have left it on; treat the arm as "
                f"powered: {advice}"
            )
        return "every servo read its torque off"

    def _check_servo(self, joint) -> None:
        sid, dev = joint.servo_id, self.name
        try:
            model = self._bus.ping(sid)
        except CommunicationError as exc:
            raise self._unanswered(joint, exc) from exc
        if model != joint.model_number:
            raise ConfigMismatchError(
                dev,
                f"model number {model} ({ct.MODEL_NAMES.get(model, 'unknown')}) but the config "
                f"expects {joint.model_number} ({ct.MODEL_NAMES[joint.model_number]}); fix "
                f"model_number or servo_id in [arm.dynamixel.{self._role(joint)}]",
                "connect",
                sid,
            )
        self._check_status_return_level(joint)
        status = self._bus.read(sid, ct.HARDWARE_ERROR_STATUS, check_alert=False)
        if status:
            raise self._bus.hardware_fault(sid, "connect", status)
        mode = self._bus.read(sid, ct.OPERATING_MODE)
        if mode != joint.mode:
            raise ConfigMismatchError(
                dev,
                f"operating mode {mode} but the config expects {int(joint.mode)} "
                f"({joint.operating_mode}); set it with Dynamixel Wizard (torque off)",
                "connect",
                sid,
            )
        drive = self._bus.read(sid, ct.DRIVE_MODE)
        if drive & 0x05:
            raise ConfigMismatchError(
                dev,
                f"drive mode 0x{drive:02X} has the reverse or time-based bit set; the driver "
                "expects 0 (set 'direction' in the config instead)",
                "connect",
                sid,
            )
        if drive & ct.DRIVE_MODE_TORQUE_ON_BY_GOAL_UPDATE:
            firmware = self._bus.read(sid, ct.FIRMWARE_VERSION)
            if firmware >= ct.TORQUE_ON_BY_GOAL_UPDATE_FIRMWARE:
                raise ConfigMismatchError(
                    dev,
                    f"drive mode 0x{drive:02X} has bit 3 'Torque On by Goal Update' set "
                    f"(firmware {firmware}): any goal written after an emergency stop would "
                    "switch torque back on and move the arm; clear bit 3 of Drive Mode "
                    "(address 10) with Dynamixel Wizard (torque off)",
                    "connect",
                    sid,
                )
        self._check_velocity_limit(joint)

    def _check_status_return_level(self, joint) -> None:  # type: ignore[no-untyped-def]
        """Refuse, before any write, a servo whose Status Return Level (68) is below 2.

        Why: the driver confirms every write by its status packet, and a servo set to level 1
        by another program (it saves bus time) answers pings and reads but no write. Its first
        write (torque off for the position limits) then timed out with "COMM_RX_TIMEOUT …
        check power, cabling, id and baud rate", of a servo that had just answered. Level 0
        (ping only) leaves even this read unanswered, which is said as such. The register is
        in the RAM area, 2 at power-on (ROBOTIS e-manual, X-series control table)."""
        sid, role = joint.servo_id, self._role(joint)
        fix = (
            f"it is 2 at power-on (RAM area): {self.power_cycle}, or set Status Return Level "
            "(address 68) to 2 with Dynamixel Wizard 2.0"
        )
        try:
            level = self._bus.read(sid, ct.STATUS_RETURN_LEVEL, check_alert=False)
        except CommunicationError as exc:
            if not no_reply(exc):
                raise
            raise CommunicationError(
                self.name,
                f"the {role} joint's servo answers its ping but no read: its Status Return "
                f"Level (address 68) is most likely 0 (answer pings only); {fix}",
                exc.command,
                sid,
                exc.result,
            ) from exc
        if level < 2:
            raise ConfigMismatchError(
                self.name,
                f"Status Return Level (address 68) is {level}: the {role} joint's servo "
                "answers pings and reads but no write, so no command could be confirmed; "
                f"{fix}",
                "connect",
                sid,
            )

    def _unanswered(self, joint, exc: CommunicationError) -> CommunicationError:  # type: ignore[no-untyped-def]
        """A configured servo that does not answer its ping, with what does answer on the bus.

        Why: the error had been the SDK's "There is no status packet!" with "check power,
        cabling, id and baud rate" whatever the cause. A broadcast Ping (read-only) tells the
        causes apart: other servos answering at this baud rate mean a wrong ``servo_id`` (the
        answering ids and models are named, with the config key to set); none answering means
        power, cabling, the baud rate or the servos' protocol (a servo set to Protocol 1.0,
        Protocol Type = 1 at address 13, does not answer Protocol 2.0 packets: ROBOTIS
        e-manual, X-series control table)."""
        found = self._bus.scan()
        if not found:
            if found is None:
                return exc
            self._tell(
                f"{self.name}: no servo answers at {self.settings.baudrate} baud (the "
                "[arm.dynamixel] baudrate); looking for the servos at the other X-series "
                "rates, a read-only broadcast ping each (up to about 10 s)."
            )
            rates: list[int] = []
            elsewhere = self._bus.scan_rates(_RATES_TO_TRY, rates)
            if elsewhere is not None:
                return self._at_other_rate(joint, exc, *elsewhere)
            tried = f", nor at {', '.join(map(str, rates))}" if rates else ""
            return CommunicationError(
                self.name,
                f"no reply to its ping (COMM_RX_TIMEOUT), and no servo at all answers a "
                f"broadcast ping on {self._bus.port.getPortName()!r} at "
                f"{self.settings.baudrate} baud (the [arm.dynamixel] baudrate){tried}: check "
                "the servos' power and cabling, and that the servos speak "
                "Protocol 2.0 (Protocol Type, address 13; a servo set to Protocol 1.0, as "
                "AX and MX servos ship, answers none of these pings)",
                exc.command,
                joint.servo_id,
                exc.result,
            )
        if joint.servo_id in found:
            return exc  # it answers a broadcast: a flaky line, said as the SDK said it
        role = self._role(joint)
        others = {j.servo_id: self._role(j) for j in self.settings.joints if j is not joint}
        spare = {i: m for i, m in found.items() if i not in others}
        if not spare:  # only the arm's other joint answers
            seen = ", ".join(f"servo {i} (the {others[i]} joint)" for i in sorted(found))
            # this one set to another rate than the other joint (a servo replaced, or its
            # rate changed alone), read-only as the scan at connect: it had been told to
            # check its cable first, with no word of the rate that answers
            elsewhere = self._bus.scan_rates(_RATES_TO_TRY)
            if elsewhere is not None and joint.servo_id in elsewhere[1]:
                rate = elsewhere[0]
                return CommunicationError(
                    self.name,
                    f"no reply at {self.settings.baudrate} baud (the [arm.dynamixel] "
                    f"baudrate), while {seen} does; the {role} servo answers at {rate} baud: "
                    "the servos on one bus must share one rate, so set its Baud Rate "
                    f"(address 8) to {self.settings.baudrate} with Dynamixel Wizard 2.0",
                    exc.command,
                    joint.servo_id,
                    exc.result,
                )
            message = (
                f"no servo with id {joint.servo_id} answers at {self.settings.baudrate} baud, "
                f"while {seen} does: check the {role} servo's cable and the chain between "
                f"the servos, then its id and baud rate (Dynamixel Wizard 2.0) against "
                f"[arm.dynamixel.{role}] servo_id"
            )
        else:
            answering = ", ".join(
                f"{i} ({ct.MODEL_NAMES.get(m, f'model {m}')})" for i, m in sorted(spare.items())
            )
            one = len(spare) == 1
            message = (
                f"no servo with id {joint.servo_id} answers at {self.settings.baudrate} baud, "
                f"but {'servo' if one else 'servos'} {answering} {'does' if one else 'do'}: "
                f"set servo_id in [arm.dynamixel.{role}] to the id of the {role} servo "
                "(Dynamixel Wizard 2.0 shows and changes ids; no two servos may share one)"
            )
        return CommunicationError(self.name, message, exc.command, joint.servo_id, exc.result)

    def _at_other_rate(  # type: ignore[no-untyped-def]
        self, joint, exc: CommunicationError, rate: int, found: dict[int, int]
    ) -> CommunicationError:
        """Servos silent at the configured baud rate that answer at another: that rate, the
        servos and the key to set (the message had left the user to scan every rate with
        Dynamixel Wizard 2.0)."""
        answering = ", ".join(
            f"{i} ({ct.MODEL_NAMES.get(m, f'model {m}')})" for i, m in sorted(found.items())
        )
        one = len(found) == 1
        return CommunicationError(
            self.name,
            f"no reply to its ping (COMM_RX_TIMEOUT) on {self._bus.port.getPortName()!r} at "
            f"{self.settings.baudrate} baud (the [arm.dynamixel] baudrate), but "
            f"{'servo' if one else 'servos'} {answering} {'answers' if one else 'answer'} "
            f"a broadcast ping at {rate} baud: set baudrate = {rate} in [arm.dynamixel] (or "
            "set the servos' Baud Rate, address 8, with Dynamixel Wizard 2.0)",
            exc.command,
            joint.servo_id,
            exc.result,
        )

    def _role(self, joint) -> str:  # type: ignore[no-untyped-def]
        """The joint's table in the rig config (``azimuth`` or ``elevation``): an error about a
        setting names where to change it (it had named only the servo id)."""
        return "azimuth" if joint is self.settings.azimuth else "elevation"

    def _check_velocity_limit(self, joint) -> None:
        """The profile velocity within the servo's Velocity Limit (44), checked before any write.

        A Profile Velocity above the Velocity Limit is refused (Data Limit Error, in a generic
        e-manual include) or capped (not verified for the X series): either way the arm would
        not move at the configured speed, and the limit differs per model (factory, 0.229
        rev/min units: XM540-W270 128 = 29.3 rpm, XH430-W350 130, XM430-W350 200, XL430-W250
        265, XL330-M288 445; ROBOTIS e-manual): a
        speed fine for one servo failed a connect on another half-way through, after the
        position limits were rewritten, as a bare "data limit error" on a register write."""
        limit = self._bus.read(joint.servo_id, ct.VELOCITY_LIMIT)
        if joint.velocity_units > limit:
            raise ConfigMismatchError(
                self.name,
                f"[arm.dynamixel.{self._role(joint)}] profile_velocity_rpm = "
                f"{joint.profile_velocity_rpm:g} (register value "
                f"{joint.velocity_units}) exceeds the servo's Velocity Limit {limit} "
                f"({limit * ct.RPM_PER_VELOCITY_UNIT:.1f} rpm, "
                f"{ct.MODEL_NAMES.get(joint.model_number, 'this model')}); lower "
                "profile_velocity_rpm, or raise Velocity Limit (address 44) with Dynamixel "
                "Wizard (torque off) within the model's range",
                "connect",
                joint.servo_id,
            )

    def _check_position_limits(self, joint) -> None:
        """Servo-side limits equal to the config's, so the servo refuses what the config does."""
        sid = joint.servo_id
        lo, hi = joint.tick_limits
        have = (
            self._bus.read(sid, ct.MIN_POSITION_LIMIT),
            self._bus.read(sid, ct.MAX_POSITION_LIMIT),
        )
        if have == (lo, hi):
            return
        if not self.settings.sync_position_limits:
            raise ConfigMismatchError(
                self.name,
                f"Min/Max Position Limit are {have[0]}..{have[1]} but the config gives {lo}..{hi};"
                " set sync_position_limits = true or write them with Dynamixel Wizard",
                "connect",
                sid,
            )
        log.info("%s: servo %d position limits %s -> %s", self.name, sid, have, (lo, hi))
        # EEPROM is writable only with torque off; on a two-axis servo (2XL430) only with both
        # axes' torque off: the arm's other axis of that model is taken to be its sibling (a
        # 2XL430 pan-tilt). With the other axis still holding from an earlier session (torque
        # policy "hold"), changing the limits in the config had failed the connect on a bare
        # "access error"
        off = [sid]
        if joint.model_number in ct.DUAL_AXIS_MODELS:
            off = [
                j.servo_id for j in self.settings.joints if j.model_number in ct.DUAL_AXIS_MODELS
            ]
        self._refuse_torque_off_away_from_park(joint, off, have, (lo, hi))
        for servo_id in off:
            self._bus.write(servo_id, ct.TORQUE_ENABLE, 0)
        self._bus.write(sid, ct.MIN_POSITION_LIMIT, lo)
        self._bus.write(sid, ct.MAX_POSITION_LIMIT, hi)
        again = (
            self._bus.read(sid, ct.MIN_POSITION_LIMIT),
            self._bus.read(sid, ct.MAX_POSITION_LIMIT),
        )
        if again != (lo, hi):
            raise ConfigMismatchError(
                self.name, f"position limits read back as {again}, wrote {(lo, hi)}", "connect", sid
            )

    def _refuse_torque_off_away_from_park(  # type: ignore[no-untyped-def]
        self, joint, off: list[int], have: tuple[int, int], want: tuple[int, int]
    ) -> None:
        """Refuse, before any write, to switch torque off (to write the position limits, EEPROM)
        on a servo that holds the arm away from its park pose.

        Why: the EEPROM area is writable only with Torque Enable (64) cleared to 0 (ROBOTIS
        e-manual, X-series control table), so the limits are written torque off; but a
        servo keeps its torque while powered, and an earlier session may have left the arm
        holding anywhere (``torque_policy = "hold"``, ``"release_on_close"`` away from park, a
        crash). The connect had switched it off there without a word: the elevation joint,
        back-driven by the lamp's weight, drops towards the object. At the park pose the arm
        rests safely (as ``release_on_close`` judges it); elsewhere nothing is written."""
        holding = []
        for j in self.settings.joints:
            if j.servo_id not in off:
                continue
            if self._bus.read(j.servo_id, ct.TORQUE_ENABLE, check_alert=False):
                holding.append(j)
        if not holding or self._at_park():
            return
        role = self._role(joint)
        raise SafetyViolation(
            self.name,
            f"the {role} servo's Min/Max Position Limit are {have[0]}..{have[1]} but the "
            f"config gives {want[0]}..{want[1]}, and writing them (EEPROM) needs its torque "
            f"off, while {self._servos_named(holding)} holds the arm away from its park pose "
            "(Torque Enable read back ON, e.g. since an earlier session): a torque-off there "
            "would let the lamp drop onto the object. Nothing was written; park the arm "
            "under the config's earlier limits first (rti-rig check parks it, with "
            "park_after_session on), or support the arm and "
            f"{self.power_cycle} (the servos then start with torque off), then run the "
            "command again",
            "connect",
            joint.servo_id,
        )

    def _at_park(self, present: tuple[int, ...] | None = None) -> bool:
        """Whether the arm reads back within :attr:`PARKED_TICKS` of its park pose (``present``:
        ticks already read, as past a faulted servo's Alert bit; else read now)."""
        s = self.settings
        park = self.kin.ticks_of_pose(s.park_azimuth_deg, s.park_elevation_deg)
        present = self.joint_ticks() if present is None else present
        return (
            max(abs(int(a) - int(b)) for a, b in zip(present, park, strict=True))
            <= self.PARKED_TICKS
        )

    def _check_in_limits(self) -> None:
        """Homing check: refuse to move an arm that powers up outside its safe range or inside
        the keep-out cone (absolute encoders: the reading is the pose, no search needed)."""
        ticks = self.joint_ticks()
        for joint, t in zip(self.settings.joints, ticks, strict=True):
            lo, hi = joint.tick_limits
            if not lo <= t <= hi:
                raise SafetyViolation(
                    self.name,
                    f"present position {t} is outside the configured range {lo}..{hi}; move the "
                    f"arm by hand into its range {self._torque_for_hands()} or fix "
                    "zero_offset_ticks",
                    "connect",
                    joint.servo_id,
                )
        reason = self.kin.ticks_reason(*ticks, what="position")
        if reason:
            raise SafetyViolation(
                self.name,
                f"the arm is not in a safe pose ({reason}); move it "
                f"by hand out of the keep-out cone {self._torque_for_hands()}",
                "connect",
            )

    def _torque_for_hands(self) -> str:
        """What the servos' torque is, as read, for a user told to move the arm by hand.

        Why read: the refusal had said "(torque is off)" as a fact. With ``torque_policy =
        "hold"`` the servos keep holding after a session or check ends, and they still do when
        the next connect refuses the pose (a wider keep-out cone in the config, say): a user
        told the torque was off pushed against servos holding under torque. And ``home`` runs
        this check on a connected arm, torque on."""
        on, unknown = self._torque_as_read()
        if on:
            held = self._servos_named(on)
            return (
                f"(its torque is ON, as read: {held} still holding, e.g. since an earlier "
                f"session with torque_policy = 'hold'; {self.power_cycle}, which starts them "
                "with torque off, supporting the arm so that it cannot drop onto the object, "
                "then move it)"
            )
        if unknown:
            return (
                "(whether its torque is off could not be read: power-cycle the servos first, "
                f"supporting the arm: {self.power_cycle})"
            )
        return "(its torque is off, as read)"

    def _torque_as_read(self) -> tuple[list[Any], list[Any]]:
        """The joints whose servo reads Torque Enable on, and those whose read failed."""
        on, unknown = [], []
        for joint in self.settings.joints:
            try:
                if self._bus.read(joint.servo_id, ct.TORQUE_ENABLE, check_alert=False):
                    on.append(joint)
            except DynamixelError:
                unknown.append(joint)
        return on, unknown

    def _servos_named(self, joints: list[Any]) -> str:
        return ", ".join(f"servo {j.servo_id} ({self._role(j)})" for j in joints)

    def close(self) -> None:
        """Lamp off, motion stopped (torque policy applied), port released — the arm is not moved.

        Parking is a move, and whether to move is policy: after a session the rig parks the arm
        first (``ArmLighting.safe``), after an emergency stop or a failed self-test it must not
        (the arm may be stopped against an obstruction). So ``close`` never parks; call
        ``park()`` before it when that is wanted. Safe to call twice and after a failed
        ``connect``. The first error during teardown is re-raised after the port has been
        closed; any later one is said through :meth:`_tell`."""
        if not self._connected:
            self._bus.close()
            return
        first: BaseException | None = None
        # "hold" sends no torque-off and reads nothing back: recorded as such (the release's
        # record is made by the release itself, once it has read the servos back)
        hold = self.settings.torque_policy != "release_on_close"
        self._torque_at_close = TorqueAtClose(self.settings.torque_policy, False) if hold else None
        steps: list[tuple[str, Callable[[], None], str]] = [
            ("the lamp-off", lambda: self.lamp(False), "check that the lamp is off"),
            (
                "the stop",
                self.stop,
                "the arm may still be moving: switch off the servos' power if it is",
            ),
        ]
        if self.settings.torque_policy == "release_on_close":
            steps.append(
                ("the torque release", self._release_if_parked, "its torque may still be on")
            )
        for what, step, advice in steps:
            try:
                step()
            except Exception as exc:  # keep tearing down
                if first is None:
                    first = exc  # raised below, and said by whoever called close
                else:  # a second failure is said in its own line, never lost
                    self._tell(
                        f"{self.name}: while closing after an earlier failure, {what} failed "
                        f"too: {exc}; {advice}."
                    )
        self._connected = False
        self._bus.close()
        if first is not None:
            raise first

    #: How close (ticks, each joint) to the park pose counts as parked for releasing torque.
    PARKED_TICKS = 8

    def _release_if_parked(self) -> None:
        """``release_on_close``: torque off only at the park pose, where the arm rests safely.

        Anywhere else a limp arm can drop onto the object, so torque stays on (holding) and the
        reason is logged: close never parks (see :meth:`close`)."""
        if self._at_park():
            self._bus.broadcast_write(ct.TORQUE_ENABLE, 0)
            self.torque_released = True
            # a broadcast write gets no status reply: whether each servo let go is read back
            self._torque_after_release = self._torque_as_read()
            self._torque_at_close = self._torque_record(True, *self._torque_after_release)
            return
        # kept on: read back, so that the record (and the words) say what the servos hold,
        # not what the policy meant (a servo an overload shut down reads its torque off)
        on, unknown = self._torque_as_read()
        self._torque_at_close = self._torque_record(False, on, unknown)
        if len(on) == len(self.settings.joints):
            self._tell(
                f"{self.name}: torque stays on: the arm is not at its park pose, and "
                'torque_policy = "release_on_close" releases it only there, where it cannot '
                f"drop onto the object. Park it with {self._check_command()} before switching "
                "off the servos' power."
            )
            return
        off = [j for j in self.settings.joints if j not in on and j not in unknown]
        read = "; ".join(
            f"{what} from {self._servos_named(joints)}"
            for what, joints in (("reads back ON", on), ("reads back OFF (limp)", off))
            if joints
        )
        unread = f"; not read back from {self._servos_named(unknown)}" if unknown else ""
        self._tell(
            f"{self.name}: no torque-off sent: the arm is not at its park pose, and "
            'torque_policy = "release_on_close" releases it only there; Torque Enable '
            f"{read}{unread}. Support the arm before switching off the servos' power, and "
            f"park it with {self._check_command()}."
        )

    def _check_command(self) -> str:
        """The command that parks this arm and moves nothing else (``check --park-only``; the
        plain check walks every self-test pose first), its rig config named as shell words so
        that it pastes and runs (a bare 'rti-rig check' is refused for its missing config);
        quoted with a placeholder only for an arm opened without a rig config (manual tools)."""
        config = self._bus.config
        if not config:
            return "'rti-rig check RIG_CONFIG --park-only'"
        return f"rti-rig check {shell_word(config)} --park-only"

    def _torque_record(self, off_sent: bool, on: list[Any], unknown: list[Any]) -> TorqueAtClose:
        """The close's :class:`TorqueAtClose` from Torque Enable as read back."""
        read = {
            j.servo_id: "on" if j in on else "unread" if j in unknown else "off"
            for j in self.settings.joints
        }
        return TorqueAtClose("release_on_close", off_sent, read)

    def torque_at_close(self) -> TorqueAtClose | None:
        """What the last close established of the torque (see :class:`TorqueAtClose`); None
        when that close did not get as far as its torque policy (a failed read of the pose
        before the release: the failure is the close's error) or was never connected."""
        return self._torque_at_close

    def listen(self, say: Callable[[str], None] | None) -> None:
        """Have what a user must know as it happens (the search for the servos at other baud
        rates, a torque kept on at the close, a second failure while making the arm safe)
        said through ``say``; ``None`` stops it.

        Why: these had been warning and error records, which the command line (configuring no
        logging) printed raw on stderr, in the middle of the progress bar."""
        self._say = say

    def _tell(self, text: str) -> None:
        """Say ``text`` once, through the listener, or as a warning record with none (never
        lost); kept in :attr:`said`."""
        self.said.append(text)
        say_or_log(text, self._say, log)

    def resends(self) -> tuple[list[str], str | None]:
        """The commands sent once more after a lost or damaged status packet that then got
        their answer (for the session's manifest), and the one line that counts them for the
        user (None: none)."""
        return list(self._bus.resent), resends_said(self._bus.resent)

    def lamp_servo(self) -> int | None:
        """The servo whose LED register switches the lamp (``lamp = "servo_led"``), else None:
        a ``"software"`` lamp is switched by nothing on the bus."""
        if self.settings.lamp != "servo_led" or self.settings.lamp_servo_id is None:
            return None
        return int(self.settings.lamp_servo_id)

    def torque_release_note(self) -> str | None:
        """What a user must know of an arm whose last close sent its torque-off at the park
        pose (None when it did not): the park pose is not held, and whether each servo was
        read back limp.

        Why: the check said "parked" and no more, while the limp elevation joint, back-driven
        by the lamp's weight, may sink from the park pose; how far is the arm's mechanics (its
        min_deg is a software limit, which a limp joint does not keep: it falls to a mechanical
        stop, if the arm has one). And the torque-off is a broadcast write, which no servo
        answers: "the joints are limp" is said only of servos that read Torque Enable 0."""
        if not self.torque_released:
            return None
        s = self.settings
        on, unknown = self._torque_after_release
        policy = 'torque_policy = "release_on_close"'
        if on:
            release = f"to release it, support the arm and {self.power_cycle}"
            return (
                f"torque-off sent ({policy}), but Torque Enable reads back ON from "
                f"{self._servos_named(on)}: that joint still holds (the torque-off, a "
                f"broadcast no servo answers, did not reach it); {release}"
            )
        said = (
            f"torque-off sent ({policy}), Torque Enable not read back from "
            f"{self._servos_named(unknown)}: the joints may be limp and may hold no pose"
            if unknown
            else f"torque then released ({policy}, read back off on each servo): the joints "
            "are limp and hold no pose"
        )
        return (
            f"{said}; the lamp's weight may lower the elevation joint from its park pose "
            f"({s.park_elevation_deg:g}°), past its lower limit (min_deg = "
            f"{s.elevation.min_deg:g}°, a software limit a limp joint does not keep), until the "
            'arm meets a mechanical stop; to keep it where it parked, set torque_policy = "hold"'
        )

    def __enter__(self) -> DynamixelArm:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- capability -------------------------------------------------------------------------
    def unreachable_reason(self, direction: NDArray[np.float64]) -> str | None:
        return self.kin.unreachable_reason(direction)

    def move_to(self, direction: ArrayLike) -> NDArray[np.float64]:
        """Move the lamp to ``direction``; wait until in position; return the direction reached."""
        try:
            d = as_direction(direction)
        except ValueError as exc:
            raise UnreachableError(self.name, direction, f"not a 3-vector: {exc}") from exc
        current_az = None
        if self._goal is not None:
            current_az = self.kin.pose_of_ticks(*self._goal)[0]
        pose, reason = self.kin.solve(d, current_az)
        if pose is None:
            raise UnreachableError(self.name, np.round(d, 6).tolist(), reason or "unknown")
        # named by the light's azimuth and elevation, as the .lp and rti-rig's other words give
        # them (0-360°), not by the unit vector (its numpy repr, "move_to [0.9968 0.     0.0805]",
        # had been said), nor by the joint's angle alone: a turn away on a joint limited to
        # -170..170°, a light at az 200° had been said as "az -160.0°", named here as the joint
        joint_az, el = pose
        light_az = float(az_el_from_direction(d)[0])
        joint = "" if abs(joint_az - light_az) < 0.05 else f" (azimuth joint at {joint_az:.1f}°)"
        return self._move_ticks(
            self.kin.ticks_of_pose(*pose), f"move to az {light_az:.1f}°, el {el:.1f}°{joint}"
        )

    def park(self, cancelled: Callable[[], bool] | None = None) -> None:
        """Move to the park pose and wait until in position.

        ``cancelled`` is asked before each poll of the wait (every ``poll_interval_s`` plus one
        bus round trip): once it says True the park is given up and the arm held where it
        stands (:meth:`stop`: goal = present position, torque stays on; a torque-off would
        drop the lamp onto the object), then :class:`MoveCancelled` is raised. Why: the
        teardown's park holds Ctrl-C and SIGTERM (a stop must not cut the lamp-off), and a
        user's stop during a park sat out the whole move, up to ``move_timeout_s``."""
        s = self.settings
        goal = self.kin.ticks_of_pose(s.park_azimuth_deg, s.park_elevation_deg)
        self._move_ticks(goal, "park", cancelled)

    @property
    def park_pose_deg(self) -> tuple[float, float]:
        """(azimuth, elevation) of the park pose: what a read-back position is compared to."""
        return (self.settings.park_azimuth_deg, self.settings.park_elevation_deg)

    def home(self) -> None:
        """Check the arm is inside its limits (absolute encoders: no search needed) and park."""
        self._require_connected("home")
        self._check_in_limits()
        self.park()

    def lamp(self, on: bool) -> None:
        """Switch the lamp (with ``lamp = "servo_led"``: the LED register of its servo).

        Switching it off is done by a Write the servo carries out even while it reports a
        hardware fault: the Alert bit of its reply says the servo has a problem, not that the
        Write failed (an error number would; ROBOTIS e-manual, Protocol 2.0, Status Packet,
        Error). So the Alert does not fail the lamp-off — it had, and a session stopped by an
        overload on the lamp's servo reported "lamp off" as failed with the lamp off, and kept
        calling it on. The fault itself is reported by the move or stop that meets it.
        Switching on still refuses a servo in fault."""
        if self.settings.lamp == "servo_led" and self._connected:
            self._bus.write(
                int(self.settings.lamp_servo_id), ct.LED, 1 if on else 0, check_alert=bool(on)
            )
        self._lamp_on = bool(on)

    @property
    def lamp_is_on(self) -> bool:
        return self._lamp_on

    def stop(self) -> None:
        """Stop motion by making each joint's present position its goal (torque stays on).

        A hold is not a move: it is written wherever the arm stands, clamped only into each
        joint's limits, not refused by the keep-out gate (an arm found inside the cone was
        left moving because its hold was "unsafe"). A joint whose servo cannot be read (a
        hardware fault, no reply) does not keep the others from being held (a fault on one
        servo had left the other swinging on to its goal, torque on); the error then names
        what was held and what was not."""
        if not self._connected:
            return
        if self._emergency_stopped:
            # torque is off on purpose: writing a goal now is pointless at best, and on a servo
            # whose Drive Mode has "Torque On by Goal Update" it would switch torque back on
            return
        roles = dict(zip(self.settings.servo_ids, ("azimuth", "elevation"), strict=True))
        present: dict[int, int] = {}
        alerted: dict[int, HardwareFaultError] = {}
        failed: list[tuple[int, DynamixelError]] = []
        for joint in self.settings.joints:
            sid = joint.servo_id
            try:
                try:
                    ticks = self._bus.read(sid, ct.PRESENT_POSITION)
                except HardwareFaultError as exc:
                    if exc.torque_on is not True:
                        raise  # limp, or its torque unknown: not claimed held
                    # a fault the servo does not shut down for leaves the joint driven: it
                    # must be held like the others, not reported limp
                    ticks = self._bus.read(sid, ct.PRESENT_POSITION, check_alert=False)
                    alerted[sid] = exc
                present[sid] = clamp_ticks(joint, ticks)
            except DynamixelError as exc:  # a limp or silent servo: hold the others anyway
                failed.append((sid, exc))
        if not failed and not alerted:
            self._bus.sync_write(ct.GOAL_POSITION, present)  # both at once, as a move's goal
        else:
            for sid in list(present):
                try:
                    self._bus.write(
                        sid, ct.GOAL_POSITION, present[sid], check_alert=sid not in alerted
                    )
                except DynamixelError as exc:
                    failed.append((sid, exc))
                    del present[sid]
        for sid, fault in alerted.items():
            # said once per servo and fault (a teardown stops the arm twice: its stop, then the
            # close's), and only as a detail: the alert itself is the error said by whoever met it
            if sid in present and (sid, fault.status) not in self._alerts_said:
                self._alerts_said.add((sid, fault.status))
                log.info("%s: servo %d held despite a hardware alert: %s", self.name, sid, fault)
        if len(present) == len(self.settings.servo_ids) or self._goal is not None:
            # a joint not held keeps the goal it was last sent (a later move's turn choice
            # starts from where each joint is headed)
            old = self._goal or (0, 0)
            self._goal = tuple(  # type: ignore[assignment]
                present.get(sid, old[k]) for k, sid in enumerate(self.settings.servo_ids)
            )
        if not failed:
            return
        said = "; ".join(
            [
                f"servo {sid} ({roles[sid]}) held where it is"
                + (" (hardware alert, torque still on)" if sid in alerted else "")
                for sid in present
            ]
            + [
                f"{roles[sid]}: {exc}"
                + (
                    # a limp azimuth lets the arm turn about the vertical, not sag
                    (" (the arm may sag)" if roles[sid] != "azimuth" else " (the arm turns freely)")
                    if isinstance(exc, HardwareFaultError) and exc.torque_on is False
                    else " — no reply: unpowered, it is limp and "
                    + ("the arm may sag" if roles[sid] != "azimuth" else "the arm turns freely")
                    + "; powered, it "
                    "may still be moving to its last goal, a pose checked safe before it was "
                    "sent; look at the arm before touching it"
                    if _no_reply(exc)
                    else " — it may still be moving to its last goal, a pose checked safe "
                    "before it was sent; switch the arm's power off if it does not stop"
                )
                for sid, exc in failed
            ]
        )
        # what was read of each joint not held, for the lights line: a servo that shut itself
        # off after a fault (torque read off) is limp, not holding its last goal
        unheld = tuple(
            UnheldJoint(
                roles[sid],
                sid,
                isinstance(exc, HardwareFaultError),
                exc.torque_on if isinstance(exc, HardwareFaultError) else None,
                _no_reply(exc),
            )
            for sid, exc in failed
        )
        raise StopIncompleteError(self.name, f"stop incomplete: {said}", unheld) from failed[0][1]

    def emergency_stop(self) -> str:
        """Torque off on every servo now (one broadcast packet, no reply to wait for), then
        each servo's Torque Enable read back; returns what that established, said as a
        sentence ("torque off confirmed …" only when every servo read 0).

        Use when the bus may be unreliable or the arm is hitting something: the arm goes limp
        and may drop under gravity, which is why ``stop`` (hold) is the normal safe stop.

        Why the read-back: a broadcast gets no status packet (ROBOTIS e-manual, Protocol 2.0:
        only Ping, Sync Read and Bulk Read are answered at the broadcast ID), so a lost packet
        left a joint held unseen while the stop returned as if the arm were limp. A Read is
        answered at Status Return Level 1 or 2 (connect requires 2): it is sent after the
        torque-off, never before it, each bounded by the SDK's packet timeout (tens of ms) and
        retried once, so an unanswering servo costs well under a second and never hangs the
        stop; it is then named as not read back, not as limp."""
        self._emergency_stopped = True
        self._bus.broadcast_write(ct.TORQUE_ENABLE, 0)
        if self.settings.lamp == "servo_led":
            # the lamp hangs on a servo's LED output: it goes off only by a write (the lamp
            # had been recorded as off with the LED still lit); broadcast, no reply to wait for
            self._bus.broadcast_write(ct.LED, 0)
        self._lamp_on = False
        on, unknown = self._torque_as_read()
        said = ["torque-off sent to every servo (one broadcast, which no servo answers)"]
        if on:
            said.append(
                f"Torque Enable reads back ON from {self._servos_named(on)}: that joint still "
                "holds (the broadcast did not reach it); switch the servos' power off"
            )
        if unknown:
            said.append(
                f"Torque Enable not read back from {self._servos_named(unknown)} (no answer): "
                "it may still hold; switch the servos' power off if it does"
            )
        if on or unknown:
            return "; ".join(said)
        return (
            "torque off confirmed: Torque Enable reads back 0 on "
            f"{self._servos_named(list(self.settings.joints))}; the joints are limp and the "
            "lamp's weight may lower the arm"
        )

    #: Longest wait (s) for a rebooted servo to answer a ping again. The e-manual gives no
    #: restart time; XC330s answer again after ~0.4 s, and ROBOTIS's Arduino code is reported
    #: to wait 3 s after a Reboot (ROBOTIS-GIT/emanual issue #1698), so 3 s covers both.
    REBOOT_WAIT_S = 3.0
    #: Pause between two pings while waiting for a rebooted servo.
    REBOOT_POLL_S = 0.05

    def reboot(self) -> None:
        """Reboot both servos (clears a hardware fault), wait until each answers again, and
        reconnect-style re-check them.

        Why the wait: a servo acknowledges the Reboot instruction at once, then answers nothing
        while it restarts, so the reconnect's first ping, sent straight after, went unanswered
        on a real servo ("COMM_RX_TIMEOUT … check power, cabling, id and baud rate")."""
        for joint in self.settings.joints:
            self._bus.reboot(joint.servo_id)
        self._connected = False
        for joint in self.settings.joints:
            self._wait_restarted(joint)
        self._bus.close()
        self.connect()

    def reboot_faulted(self) -> list[RebootOutcome]:
        """Reboot only the servos whose Hardware Error Status is set and whose torque is off,
        wait until each answers again, and read its status and torque back; nothing else is
        written and no torque is switched on (the port is closed again: a ``connect``, through
        every check, is what drives the arm next). One per joint, in the config's order.

        Why: no command cleared a servo's fault (overload …), though its Reboot instruction
        does (ROBOTIS e-manual, Shutdown (63): "REBOOT is the only method to reset Torque
        Enable(64) to '1' after the shutdown"); users were sent to a power cycle or Dynamixel
        Wizard. A faulted servo whose torque is still on (an input-voltage error the XL430's
        Shutdown does not select) is not rebooted: a reboot switches its torque off, and the
        joint it holds would drop."""
        if self._connected:
            raise DynamixelError(
                self.name, "the arm is connected: close it before rebooting", "reboot faulted"
            )
        self._bus.open(self.settings.baudrate)
        out: list[RebootOutcome] = []
        try:
            for joint in self.settings.joints:
                sid, role = joint.servo_id, self._role(joint)
                try:
                    self._bus.ping(sid)
                except CommunicationError as exc:
                    raise self._unanswered(joint, exc) from exc
                status = self._bus.read(sid, ct.HARDWARE_ERROR_STATUS, check_alert=False)
                if not status:
                    out.append(RebootOutcome(role, sid, 0, rebooted=False))
                    continue
                if self._bus.read(sid, ct.TORQUE_ENABLE, check_alert=False):
                    out.append(
                        RebootOutcome(
                            role,
                            sid,
                            status,
                            rebooted=False,
                            torque_on=True,
                            power_cycle=self._bus.power_cycle,
                        )
                    )
                    continue
                self._bus.reboot(sid)
                self._wait_restarted(joint)
                after = self._bus.read(sid, ct.HARDWARE_ERROR_STATUS, check_alert=False)
                torque = bool(self._bus.read(sid, ct.TORQUE_ENABLE, check_alert=False))
                out.append(RebootOutcome(role, sid, status, True, after, torque))
        finally:
            self._bus.close()
        return out

    def _wait_restarted(self, joint) -> None:  # type: ignore[no-untyped-def]
        """Ping ``joint``'s servo until it answers, for at most :attr:`REBOOT_WAIT_S` on the
        arm's clock; one still silent is a :class:`CommunicationError` naming it."""
        deadline = self.clock.now() + self.REBOOT_WAIT_S
        while True:
            try:
                self._bus.ping(joint.servo_id, once=True)  # this loop is the retry
                return
            except CommunicationError as exc:
                if self.clock.now() >= deadline:
                    raise CommunicationError(
                        self.name,
                        f"the {self._role(joint)} joint's servo answered no ping within "
                        f"{self.REBOOT_WAIT_S:g} s of its Reboot: switch the servos' power off "
                        "and on, check its cable, then connect again",
                        "reboot",
                        joint.servo_id,
                        exc.result,
                    ) from exc
            self.clock.sleep(self.REBOOT_POLL_S)

    # -- internals --------------------------------------------------------------------------
    def _require_connected(self, command: str) -> None:
        if not self._connected:
            raise DynamixelError(self.name, "not connected; call connect() first", command)

    def check_held(self, command: str = "check held after the capture") -> None:
        """Raise unless every joint still holds, fault-free, the pose read when its move ended
        (the pose the capture is recorded under): read after a capture, before its image is
        kept under the direction read before it.

        Why: a servo that overloaded while the shutter was open (ROBOTIS e-manual, Shutdown
        (63): torque off; Hardware Error Status (70) and the Alert bit of every status packet
        set until a reboot) leaves a limp joint, and the arm sags; the image had been kept and
        listed in lights.lp under the direction read before the capture, the fault found only
        at the next move. A fault is raised as :class:`HardwareFaultError` (servo, fault, how
        to clear it); a joint moved by more than ``in_position_tolerance_ticks`` (a sag, a
        bump) as a :class:`DynamixelError` naming the joint and how far.

        Measured from the pose reached, not from the goal: a servo holding a load settles off
        its goal (the XL430's Position I Gain (82) is 0 at the factory, so its position loop
        keeps a steady-state error under a steady load; ROBOTIS-GIT/emanual
        docs/en/dxl/x/xl430-w250.md @ 00a4b781d5a52e9b62599ea084cabc11e33b3b46: Position I Gain
        initial 0, P 640), up to the move's tolerance, and may
        creep a tick or two more; measured from the goal, an arm that settled 3 ticks short and
        crept 2 was stopped mid-session as "moved" (5 > 4) though the recorded direction was
        off by 2 ticks. The same tolerance bounds both: how far the recorded direction may be
        from where the lamp really was."""
        self._require_connected(command)
        s = self.settings
        reference = self._reached or self._goal or (None, None)
        for joint, held in zip(s.joints, reference, strict=True):
            data, error = self._bus.read_block(
                joint.servo_id, ct.STATUS_BLOCK_START, ct.STATUS_BLOCK_LENGTH
            )
            if error & p2.ERR_ALERT:
                raise self._bus.hardware_fault(joint.servo_id, command)
            off = ct.PRESENT_POSITION.address - ct.STATUS_BLOCK_START
            present = p2.to_signed(int.from_bytes(data[off : off + 4], "little"), 4)
            if held is not None and abs(present - held) > s.in_position_tolerance_ticks:
                raise DynamixelError(
                    self.name,
                    f"the {self._role(joint)} joint moved during the capture: at "
                    f"{ticks_to_joint(joint, present):.2f}° where it had reached "
                    f"{ticks_to_joint(joint, held):.2f}° (more than in_position_tolerance_ticks "
                    f"= {s.in_position_tolerance_ticks}): the image was not kept; check for a "
                    "bump or a joint that slips",
                    command,
                    joint.servo_id,
                )

    def joint_ticks(self) -> tuple[int, int]:
        """Present Position of (azimuth, elevation), signed."""
        return tuple(
            self._bus.read(j.servo_id, ct.PRESENT_POSITION)  # type: ignore[return-value]
            for j in self.settings.joints
        )

    def reached_direction(self) -> NDArray[np.float64]:
        return self.kin.direction_of_ticks(*self.joint_ticks())

    def _send_goal(self, goal: tuple[int, int], command: str) -> None:
        reason = self.kin.ticks_reason(*goal)
        if reason:
            raise SafetyViolation(self.name, f"refused before sending: {reason}", command)
        ids = self.settings.servo_ids
        self._bus.sync_write(ct.GOAL_POSITION, dict(zip(ids, goal, strict=True)))
        self._goal = goal
        self._reached = None  # until this goal is reached

    def _move_ticks(
        self, goal: tuple[int, int], command: str, cancelled: Callable[[], bool] | None = None
    ) -> NDArray[np.float64]:
        self._require_connected(command)
        self._send_goal(goal, command)
        return self._wait_in_position(goal, command, cancelled)

    def _wait_in_position(
        self, goal: tuple[int, int], command: str, cancelled: Callable[[], bool] | None = None
    ) -> NDArray[np.float64]:
        s = self.settings
        start = self.clock.now()
        while True:
            if cancelled is not None and cancelled():
                self.stop()  # the hold; a stop that fails raises its own error, said as is
                raise MoveCancelled(
                    self.name, "cancelled part-way; held where it stopped (torque on)", command
                )
            present, moving = [], False
            for joint in s.joints:
                data, error = self._bus.read_block(
                    joint.servo_id, ct.STATUS_BLOCK_START, ct.STATUS_BLOCK_LENGTH
                )
                if error & p2.ERR_ALERT:
                    raise self._bus.hardware_fault(joint.servo_id, command)
                moving = moving or data[0] != 0
                off = ct.PRESENT_POSITION.address - ct.STATUS_BLOCK_START
                present.append(p2.to_signed(int.from_bytes(data[off : off + 4], "little"), 4))
            close = all(
                abs(p - g) <= s.in_position_tolerance_ticks
                for p, g in zip(present, goal, strict=True)
            )
            if close and not moving:
                self._reached = (present[0], present[1])
                return self.kin.direction_of_ticks(*present)
            if self.clock.now() - start > s.move_timeout_s:
                late = [
                    (joint, p, g)
                    for joint, p, g in zip(s.joints, present, goal, strict=True)
                    if abs(p - g) > s.in_position_tolerance_ticks
                ]
                said = self._not_in_position(late)  # before the stop's hold rewrites goals
                try:
                    self.stop()
                except Exception as exc:  # the timeout is raised; the failed stop said too
                    self._tell(
                        f"{self.name}: the stop after the move timed out failed too: {exc}; "
                        "the arm may still be moving: switch off the servos' power if it is."
                    )
                raise MoveTimeoutError(
                    self.name,
                    f"not in position after {s.move_timeout_s:g} s: {said} (goal {goal}, "
                    f"present {tuple(present)} ticks, tolerance "
                    f"{s.in_position_tolerance_ticks})",
                    command,
                    late[0][0].servo_id if len(late) == 1 else None,
                )
            self.clock.sleep(s.poll_interval_s)

    def _not_in_position(self, late: list[tuple[Any, int, int]]) -> str:
        """Which joints a timed-out move left short, where, and why as far as can be read.

        Why: the timeout had given the two joints' ticks only, with "check for an obstruction"
        whatever happened: a user could not tell which servo stayed behind, nor that its
        torque was off — a servo restarts with torque off after a dip in its supply (RAM
        reset to its initial values, no Hardware Error left to read: ROBOTIS e-manual,
        X-series control table, RAM area), which no obstruction explains. Torque Enable is
        read for each joint left short (best effort)."""
        if not late:  # every joint close but one still reporting Moving
            return "the joints are within tolerance but still report moving; raise move_timeout_s"
        parts = []
        for joint, p, g in late:
            at = ticks_to_joint(joint, p)
            to = ticks_to_joint(joint, g)
            who = (  # one joint: the error's "servo N:" prefix names its servo already
                f"the {self._role(joint)} joint"
                if len(late) == 1
                else f"servo {joint.servo_id} ({self._role(joint)})"
            )
            text = f"{who} was at {at:.1f} deg, goal {to:.1f} deg"
            try:
                torque = self._bus.read(joint.servo_id, ct.TORQUE_ENABLE, check_alert=False)
            except DynamixelError:
                torque = None
            if torque == 0:
                text += (
                    ": its torque is off (a servo restarts with torque off after a dip in its "
                    "supply, so check that the supply carries both servos moving at once; or "
                    "another program switched it off); the joint is limp"
                )
            else:
                text += ": check for an obstruction or a load too heavy for it"
            parts.append(text)
        return "; ".join(parts)
