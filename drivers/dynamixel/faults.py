"""Named errors of the Dynamixel arm: every one says which servo, which command, what to do."""

from __future__ import annotations

from rti_rig.core.errors import DeviceError, ScheduleError, StopIncomplete, UnheldJoint
from rti_rig.drivers.dynamixel import control_table as ct


class DynamixelError(DeviceError):
    """Base class of the arm's device errors; ``servo_id`` is None for bus-wide failures."""

    def __init__(
        self, device: str, message: str, command: str | None = None, servo_id: int | None = None
    ) -> None:
        self.servo_id = servo_id
        where = f"servo {servo_id}: " if servo_id is not None else ""
        super().__init__(device, where + message, command)


class StopIncompleteError(DynamixelError, StopIncomplete):
    """The arm's stop held some joints and not others (:meth:`DynamixelArm.stop`), with what
    was read of each it did not hold (its fault, and the torque read after it)."""

    def __init__(self, device: str, message: str, unheld: tuple[UnheldJoint, ...]) -> None:
        super().__init__(device, message, "stop")
        self.unheld = unheld


class CommunicationError(DynamixelError):
    """No reply, or a corrupted reply (timeout, CRC): cabling, power, id or baud rate.

    ``result``: the SDK's communication result code the bus met (``COMM_RX_TIMEOUT``,
    ``COMM_RX_CORRUPT``, ...), None for a port that failed or would not open. Why a field: a
    servo's silence (nothing known of it, its supply perhaps gone) had been told from a
    corrupted status (a powered servo) by finding "COMM_RX_TIMEOUT" in the message, which a
    reworded message would silently break (:func:`~rti_rig.drivers.dynamixel.bus.no_reply`)."""

    def __init__(
        self,
        device: str,
        message: str,
        command: str | None = None,
        servo_id: int | None = None,
        result: int | None = None,
    ) -> None:
        self.result = result
        super().__init__(device, message, command, servo_id)


class ServoStatusError(DynamixelError):
    """The servo answered with an error number (data limit, access error, ...)."""

    def __init__(self, device: str, servo_id: int, error: int, command: str, detail: str) -> None:
        self.error = error
        super().__init__(device, detail, command, servo_id)


def _voltage_said(voltage: tuple[int, int, int]) -> str:
    """Present Input Voltage and the servo's Min/Max Voltage Limit as read (0.1 V units), said
    beside an input-voltage error.

    Why the second wording: the error is kept until a reboot, so a servo whose supply is back
    inside its limits (the next command, or a sag under load that passed) still reports it,
    and "11.1 V as read; this servo's limits are 6.0..14.0 V" left a user checking a supply
    that reads right with no idea why the servo still refuses."""
    now, low, high = (v / 10 for v in voltage)
    if low <= now <= high:
        return (
            f" (input {now:.1f} V as read, within this servo's limits {low:.1f}..{high:.1f} V "
            "now: the error was raised when the supply left them, under load or at switch-on, "
            "and is kept until a reboot)"
        )
    return f" (input {now:.1f} V as read; this servo's limits are {low:.1f}..{high:.1f} V)"


class HardwareFaultError(DynamixelError):
    """Hardware Error Status has bits set; whether torque went off is said only as read.

    A servo switches its torque off only for the faults its Shutdown register (address 63)
    selects, and the factory setting is the model's (ROBOTIS e-manual, Shutdown Initial
    Value, repo ROBOTIS-GIT/emanual docs/en/dxl/x/<model>.md): 52 = 0x34 on the XL430-W250,
    2XL430-W250, XM430-W350/W210, XH430-W350 and XM540-W270 (overheating, electrical shock,
    overload — not an input-voltage error), 53 = 0x35 on the XL330-M288 (input voltage too).
    ``torque_on`` is Torque Enable as read after the fault (``None``: it could not be read),
    so the message never claims a limp joint that is still driven, or a held one that is limp.
    ``voltage`` is (Present Input Voltage, Min, Max Voltage Limit) in 0.1 V as read for an
    input-voltage error (``None``: not read). ``config``: the rig config's path, named in the
    ``--reboot-faulted`` command the message gives (:func:`~control_table.reboot_how`), and
    ``power_cycle`` how this rig's servos are power-cycled (the other way it gives)."""

    def __init__(
        self,
        device: str,
        servo_id: int,
        status: int,
        command: str | None,
        torque_on: bool | None = None,
        voltage: tuple[int, int, int] | None = None,
        *,
        config: str | None = None,
        power_cycle: str = ct.POWER_CYCLE,
    ) -> None:
        self.status = status
        self.torque_on = torque_on
        self.voltage = voltage
        self.faults = ct.decode_hardware_error(status)
        names = ", ".join(f.name.lower().replace("_", " ") for f in self.faults) or "unknown"
        advice = "; ".join(
            ct.FAULT_ADVICE[f]
            + (
                _voltage_said(voltage)
                if f is ct.HardwareFault.INPUT_VOLTAGE and voltage is not None
                else ""
            )
            for f in self.faults
        )
        at_connect = command == "connect"
        super().__init__(
            device,
            f"hardware fault {names} (Hardware Error Status 0x{status:02X})"
            + (FOUND_AT_CONNECT if at_connect else "")
            + f"; {advice}; {ct.reboot_how(config, power_cycle, torque_on)}. "
            + torque_statement(torque_on, at_connect),
            command,
            servo_id,
        )

    @property
    def fault_names(self) -> list[str]:
        """Lower-case names, e.g. ['overload', 'overheating']."""
        return [f.name.lower() for f in self.faults]


#: Said of a fault found as the arm connects, before the command drove anything. Why: a servo
#: keeps Hardware Error Status (70) until a Reboot or a power-off (ROBOTIS e-manual, Shutdown
#: (63)), so the fault met at connect is usually one an earlier session left; the error had
#: read as if this command had just overloaded the arm ("Its torque is off (as read after the
#: fault)"), and a user looked for what the check or run had done wrong.
FOUND_AT_CONNECT = (
    " found already set as the arm connected, before this command drove it: a servo keeps "
    "its fault until it is rebooted or powered off, so it may date from an earlier session"
)


def torque_statement(torque_on: bool | None, at_connect: bool = False) -> str:
    """What a fault left of the servo's torque, as read (never assumed); ``at_connect``: read
    as the arm connected (the fault predates the command)."""
    if torque_on is False:
        when = "at connect" if at_connect else "after the fault"
        return (
            f"Its torque is off (as read {when}): the joint is limp; if the servo shut "
            "down for this fault, only a reboot lets its torque back on."
        )
    if torque_on is True:
        return (
            "This fault is not one the servo shuts down for (its Shutdown setting): its "
            "torque is still ON and the joint is still driven; switch the arm's power off "
            "before touching it."
        )
    return (
        "Whether its torque is off could not be read: treat the joint as driven and "
        "switch the arm's power off before touching it."
    )


class ConfigMismatchError(DynamixelError):
    """The servos on the bus differ from the arm config (model, mode, limits)."""


class MoveTimeoutError(DynamixelError):
    """A move did not finish in position within ``move_timeout_s``."""


class SafetyViolation(DynamixelError):
    """A command was refused before reaching the bus (limits or keep-out cone)."""


class UnreachableError(ScheduleError):
    """A light direction the arm cannot or must not reach."""

    def __init__(self, device: str, direction: object, reason: str) -> None:
        self.reason = reason
        super().__init__(f"{device}: direction {direction} is unreachable: {reason}")
