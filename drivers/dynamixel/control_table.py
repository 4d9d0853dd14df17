"""X-series control table (XL430-W250, XM430-W350/W210 and kin): addresses, sizes and units.

Sources: ROBOTIS e-manual pages for XL430-W250 and XM430-W350 (see
docs/protocols/dynamixel-arm.md). Only the registers the arm driver and the emulator use are
named here; the emulator keeps the whole table as bytes. Addresses are common to the models in
MODEL_NAMES; factory values are not (per model, cited: rti_rig.simulator.dynamixel_models).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from rti_rig.core.shell_words import shell_word


@dataclass(frozen=True)
class Register:
    """One control-table item."""

    name: str
    address: int
    size: int
    eeprom: bool = False
    writable: bool = True
    signed: bool = False


MODEL_NUMBER = Register("Model Number", 0, 2, eeprom=True, writable=False)
FIRMWARE_VERSION = Register("Firmware Version", 6, 1, eeprom=True, writable=False)
ID = Register("ID", 7, 1, eeprom=True)
BAUD_RATE = Register("Baud Rate", 8, 1, eeprom=True)
RETURN_DELAY_TIME = Register("Return Delay Time", 9, 1, eeprom=True)
DRIVE_MODE = Register("Drive Mode", 10, 1, eeprom=True)
#: Drive Mode bit 2: time-based profile (Profile Velocity/Acceleration are then times in ms).
DRIVE_MODE_TIME_BASED_PROFILE = 0x04
#: Drive Mode bit 3, "Torque On by Goal Update" (firmware 45 and later): a Goal Position written
#: while Torque Enable is 0 switches torque on and the servo moves to it (ROBOTIS e-manual,
#: X-series control table, Drive Mode).
DRIVE_MODE_TORQUE_ON_BY_GOAL_UPDATE = 0x08
TORQUE_ON_BY_GOAL_UPDATE_FIRMWARE = 45
OPERATING_MODE = Register("Operating Mode", 11, 1, eeprom=True)
SECONDARY_ID = Register("Secondary ID", 12, 1, eeprom=True)
PROTOCOL_TYPE = Register("Protocol Type", 13, 1, eeprom=True)
HOMING_OFFSET = Register("Homing Offset", 20, 4, eeprom=True, signed=True)
MOVING_THRESHOLD = Register("Moving Threshold", 24, 4, eeprom=True)
TEMPERATURE_LIMIT = Register("Temperature Limit", 31, 1, eeprom=True)
MAX_VOLTAGE_LIMIT = Register("Max Voltage Limit", 32, 2, eeprom=True)
MIN_VOLTAGE_LIMIT = Register("Min Voltage Limit", 34, 2, eeprom=True)
PWM_LIMIT = Register("PWM Limit", 36, 2, eeprom=True)
#: Not on every model: the XL430-W250 and 2XL430-W250 have no Current Limit (e-manual tables).
CURRENT_LIMIT = Register("Current Limit", 38, 2, eeprom=True)
VELOCITY_LIMIT = Register("Velocity Limit", 44, 4, eeprom=True)
MAX_POSITION_LIMIT = Register("Max Position Limit", 48, 4, eeprom=True)
MIN_POSITION_LIMIT = Register("Min Position Limit", 52, 4, eeprom=True)
SHUTDOWN = Register("Shutdown", 63, 1, eeprom=True)
TORQUE_ENABLE = Register("Torque Enable", 64, 1)
LED = Register("LED", 65, 1)
STATUS_RETURN_LEVEL = Register("Status Return Level", 68, 1)
REGISTERED_INSTRUCTION = Register("Registered Instruction", 69, 1, writable=False)
HARDWARE_ERROR_STATUS = Register("Hardware Error Status", 70, 1, writable=False)
GOAL_VELOCITY = Register("Goal Velocity", 104, 4, signed=True)
PROFILE_ACCELERATION = Register("Profile Acceleration", 108, 4)
PROFILE_VELOCITY = Register("Profile Velocity", 112, 4)
GOAL_POSITION = Register("Goal Position", 116, 4, signed=True)
REALTIME_TICK = Register("Realtime Tick", 120, 2, writable=False)
MOVING = Register("Moving", 122, 1, writable=False)
MOVING_STATUS = Register("Moving Status", 123, 1, writable=False)
PRESENT_VELOCITY = Register("Present Velocity", 128, 4, writable=False, signed=True)
PRESENT_POSITION = Register("Present Position", 132, 4, writable=False, signed=True)
PRESENT_INPUT_VOLTAGE = Register("Present Input Voltage", 144, 2, writable=False)
PRESENT_TEMPERATURE = Register("Present Temperature", 146, 1, writable=False)

#: The block the driver polls while waiting: Moving .. Present Position (122..135).
STATUS_BLOCK_START = MOVING.address
STATUS_BLOCK_LENGTH = PRESENT_POSITION.address + 4 - MOVING.address

#: Size of the emulated table (indirect data 29-56 ends at 661).
TABLE_SIZE = 662
EEPROM_END = 64  # addresses below this are EEPROM: writable only with torque off


class OperatingMode(IntEnum):
    """Operating Mode (address 11) values the arm can use."""

    POSITION = 3  # one turn, 0..4095, Min/Max Position Limit enforced by the servo
    EXTENDED_POSITION = 4  # multi-turn, +-256 rev, position limits NOT enforced by the servo


#: Model numbers of X-series servos (Model Number, address 0).
MODEL_NAMES = {
    1060: "XL430-W250",
    1090: "2XL430-W250",
    1020: "XM430-W350",
    1030: "XM430-W210",
    1000: "XH430-W350",
    1120: "XM540-W270",
    1200: "XL330-M288",
}

#: Models with two axes in one body, each axis a servo id of its own: their EEPROM can be
#: written only with the torque of *every* axis off ("Data in the EEPROM Area can only be
#: modified when Torque Enable(64) for all axis are set to '0'", ROBOTIS e-manual, X-series
#: control table, Area, 2XL430-W250 branch: ROBOTIS-GIT/emanual
#: _includes/en/dxl/x/control_table.md @ add0d1dabec2202f8ae9848b7eda8e98f9a44b0f).
DUAL_AXIS_MODELS = frozenset({1090})

TICKS_PER_REV = 4096
DEG_PER_TICK = 360.0 / TICKS_PER_REV
MAX_TICK = TICKS_PER_REV - 1
#: Extended position mode covers +-256 revolutions.
EXTENDED_TICK_LIMIT = 256 * TICKS_PER_REV - 1
#: Profile Velocity unit: 0.229 rev/min.
RPM_PER_VELOCITY_UNIT = 0.229
#: Profile Acceleration unit: 214.577 rev/min^2.
REV_MIN2_PER_ACCEL_UNIT = 214.577
#: Largest register values accepted (velocity-based profile; e-manual ranges).
MAX_PROFILE_VELOCITY_UNITS = 32767
MAX_PROFILE_ACCELERATION_UNITS = 32767


def velocity_units_to_deg_s(units: int) -> float:
    """Profile Velocity register value to servo-shaft degrees per second."""
    return units * RPM_PER_VELOCITY_UNIT * 360.0 / 60.0


def acceleration_units_to_deg_s2(units: int) -> float:
    """Profile Acceleration register value to servo-shaft degrees per second squared."""
    return units * REV_MIN2_PER_ACCEL_UNIT * 360.0 / 3600.0


class HardwareFault(IntEnum):
    """Bits of Hardware Error Status (address 70)."""

    INPUT_VOLTAGE = 0x01
    OVERHEATING = 0x04
    MOTOR_ENCODER = 0x08
    ELECTRICAL_SHOCK = 0x10
    OVERLOAD = 0x20


#: What to do about each fault; :class:`~rti_rig.drivers.dynamixel.faults.HardwareFaultError`
#: follows it with :func:`reboot_how`.
FAULT_ADVICE = {
    HardwareFault.INPUT_VOLTAGE: "check the power supply voltage against the servo's limits",
    HardwareFault.OVERHEATING: "let the servo cool down and reduce its load or duty cycle",
    HardwareFault.MOTOR_ENCODER: "the encoder failed; check the servo",
    HardwareFault.ELECTRICAL_SHOCK: "check wiring and power",
    HardwareFault.OVERLOAD: "the arm is blocked or overloaded; clear the obstruction",
}


#: How a real chain's servos are power-cycled, as the advice says it (an emulated chain's way
#: differs: :meth:`rti_rig.simulator.servo_latch.LatchedErrors.power_cycle_said`).
POWER_CYCLE = "switch the servos' power off and on"


def reboot_how(
    config: str | None = None, power_cycle: str = POWER_CYCLE, torque_on: bool | None = False
) -> str:
    """The advice's last clause: how to clear a latched fault, ``config`` (the rig config's
    path, shell-quoted) named in the command when known, so that it can be pasted; the
    placeholder ``RIG.toml`` only for a bus opened without a rig config (the manual tools).

    The two ways are the e-manual's S/W REBOOT (the Reboot instruction, which ``check
    --reboot-faulted`` sends) and H/W REBOOT (power off and on; ROBOTIS-GIT/emanual
    _includes/en/dxl/x/shutdown.md @ 048ec0de). Why: the advice had said "then reboot" for
    some faults and nothing for others (an overheated servo, told only to cool down, was
    refused again once cool, its fault still latched); and "then run rti-rig check RIG.toml
    --reboot-faulted" was said by ``run`` and ``check`` of a config they had just opened,
    which the user had to put in by hand. ``power_cycle``: how this rig's servos are power-
    cycled (an emulated chain has no power switch: "switch the servos' power off and on" was
    advice no one could follow on it).

    ``torque_on``: Torque Enable as read after the fault (None: not read). What a real servo
    does, said as it is: a Reboot clears Hardware Error Status only if the fault's cause is
    gone (the e-manual's Shutdown; a servo still too hot shuts down again, ROBOTIS forum,
    "Reboot after Shutdown with XM430-W210-R"), and ``--reboot-faulted`` reboots only a
    servo whose torque is off (a reboot switches torque off: a held joint would drop). Why:
    every fault had been told to run ``--reboot-faulted``, an input-voltage error on an
    XL430 too, whose torque stays on (its Shutdown 0x34 does not select it): the check then
    refused to reboot it, and nothing had said that a reboot before the cause is fixed
    leaves the fault set."""
    rig = shell_word(config) if config else "RIG.toml"
    cause_first = (
        "a reboot clears the fault only once its cause is gone, else the servo reports it again"
    )
    if torque_on is True:
        return (
            f"then, as its torque is on, rti-rig check {rig} --reboot-faulted will not reboot "
            f"it (a reboot switches torque off and the joint would drop): support the arm and "
            f"{power_cycle} to clear it ({cause_first}), then run rti-rig check {rig}"
        )
    only_off = "it reboots the faulted servos whose torque is off, and nothing moves"
    if torque_on is None:
        only_off = "it reboots a faulted servo only if its torque is off, and nothing moves"
    return (
        f"then run rti-rig check {rig} --reboot-faulted ({only_off}), or {power_cycle}, to "
        f"clear it ({cause_first})"
    )


def decode_hardware_error(status: int) -> list[HardwareFault]:
    """Named faults set in a Hardware Error Status byte, in bit order."""
    return [f for f in HardwareFault if status & f.value]


#: Baud Rate register codes (X-series, Protocol 2.0).
BAUD_CODES = {
    0: 9600,
    1: 57600,
    2: 115200,
    3: 1_000_000,
    4: 2_000_000,
    5: 3_000_000,
    6: 4_000_000,
    7: 4_500_000,
}
