"""The emulator's own X-series control tables, per model, as the ROBOTIS e-manual publishes
them: address, size, access (R / RW), area (EEPROM / RAM) and, where the pages agree, the
initial value; plus the Baud Rate codes, the Hardware Error Status bits and the units.

Why its own: the emulator had named every register through the driver's
``rti_rig.drivers.dynamixel.control_table``, so a register-map bug in the driver (a wrong
address or size, an item taken for writable) would have been on both sides of the wire and
every driver test against the emulator would have passed. An import-linter contract in
pyproject.toml keeps the emulator modules off the driver's table; a test cross-checks the two
(a check, not a derivation).

Sources (repository ``ROBOTIS-GIT/emanual``; rows copied by hand from the tables):

* XL430-W250: ``docs/en/dxl/x/xl430-w250.md @ 00a4b781d5a52e9b62599ea084cabc11e33b3b46``,
  "Control Table of EEPROM Area" and "Control Table of RAM Area" (the common X-series map,
  Present Load at 126, Backup Ready at 147, Startup Configuration at 60, no Current Limit).
* XM430-W350: ``docs/en/dxl/x/xm430-w350.md @ 08551725617f8cdf053bc7c28c422b9ab10dadd4``, the
  same two tables (Current Limit at 38, Goal Current at 102, Present Current at 126).
* The other models' extra EEPROM items (Startup Configuration 60, PWM Slope 62, External Port
  Mode 56..58) as :mod:`rti_rig.simulator.dynamixel_models` reads them from their pages.
* Baud Rate codes 0..7: ``_includes/en/dxl/control_table_8_baudrate_pro.md @
  3a6f8fedb9ad4496c57edf77ecb25ed76f9fd0dd`` (the X pages' range is 0 ~ 7; the stored
  ``_includes/en/dxl/x/baudrate.md @ add0d1da`` shows the Protocol 1.0 divisor list instead).
* Hardware Error Status bits: ``_includes/en/dxl/x/shutdown.md @
  53247968642942cbbdb3fb52e47d5aef4269267a`` (X branch: bit 0 Input Voltage, 2 Overheating,
  3 Motor Encoder, 4 Electrical Shock, 5 Overload).
* Units: the tables' Unit column (0.229 rev/min, 214.577 rev/min^2, 4,096 pulses a turn).

Signedness is not a column of the tables: an item is read signed where its Range (or, for
Goal/Present Position, the Extended Position mode's multi-turn range) goes below zero.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

XL430_PAGE = "docs/en/dxl/x/xl430-w250.md @ 00a4b781d5a52e9b62599ea084cabc11e33b3b46"
XM430_PAGE = "docs/en/dxl/x/xm430-w350.md @ 08551725617f8cdf053bc7c28c422b9ab10dadd4"

EEPROM = "EEPROM"
RAM = "RAM"


@dataclass(frozen=True)
class Item:
    """One row of a model's control table."""

    name: str
    address: int
    size: int
    access: str  # "R" or "RW", the table's Access column
    area: str  # EEPROM or RAM, the table it is listed in
    #: the table's Initial Value, when every page read gives the same (None: "-", or it
    #: differs per model: :mod:`rti_rig.simulator.dynamixel_models` holds those)
    initial: int | None = None
    signed: bool = False

    @property
    def writable(self) -> bool:
        return self.access == "RW"

    @property
    def eeprom(self) -> bool:
        return self.area == EEPROM


def _e(
    name: str,
    address: int,
    size: int,
    access: str = "RW",
    initial: int | None = None,
    signed: bool = False,
) -> Item:
    return Item(name, address, size, access, EEPROM, initial, signed)


def _r(
    name: str,
    address: int,
    size: int,
    access: str = "RW",
    initial: int | None = None,
    signed: bool = False,
) -> Item:
    return Item(name, address, size, access, RAM, initial, signed)


# -- the rows both pages give alike (XL430-W250 and XM430-W350) ----------------------------
MODEL_NUMBER = _e("Model Number", 0, 2, "R")
MODEL_INFORMATION = _e("Model Information", 2, 4, "R")
FIRMWARE_VERSION = _e("Firmware Version", 6, 1, "R")
ID = _e("ID", 7, 1, initial=1)
BAUD_RATE = _e("Baud Rate", 8, 1, initial=1)
RETURN_DELAY_TIME = _e("Return Delay Time", 9, 1, initial=250)
DRIVE_MODE = _e("Drive Mode", 10, 1, initial=0)
OPERATING_MODE = _e("Operating Mode", 11, 1, initial=3)
SECONDARY_ID = _e("Secondary(Shadow) ID", 12, 1, initial=255)
PROTOCOL_TYPE = _e("Protocol Type", 13, 1, initial=2)
HOMING_OFFSET = _e("Homing Offset", 20, 4, initial=0, signed=True)  # -1,044,479 ~ 1,044,479
MOVING_THRESHOLD = _e("Moving Threshold", 24, 4, initial=10)
TEMPERATURE_LIMIT = _e("Temperature Limit", 31, 1)
MAX_VOLTAGE_LIMIT = _e("Max Voltage Limit", 32, 2)
MIN_VOLTAGE_LIMIT = _e("Min Voltage Limit", 34, 2)
PWM_LIMIT = _e("PWM Limit", 36, 2, initial=885)
VELOCITY_LIMIT = _e("Velocity Limit", 44, 4)
MAX_POSITION_LIMIT = _e("Max Position Limit", 48, 4, initial=4095)
MIN_POSITION_LIMIT = _e("Min Position Limit", 52, 4, initial=0)
SHUTDOWN = _e("Shutdown", 63, 1)

TORQUE_ENABLE = _r("Torque Enable", 64, 1, initial=0)
LED = _r("LED", 65, 1, initial=0)
STATUS_RETURN_LEVEL = _r("Status Return Level", 68, 1, initial=2)
REGISTERED_INSTRUCTION = _r("Registered Instruction", 69, 1, "R", initial=0)
HARDWARE_ERROR_STATUS = _r("Hardware Error Status", 70, 1, "R", initial=0)
VELOCITY_I_GAIN = _r("Velocity I Gain", 76, 2)
VELOCITY_P_GAIN = _r("Velocity P Gain", 78, 2, initial=100)
POSITION_D_GAIN = _r("Position D Gain", 80, 2)
POSITION_I_GAIN = _r("Position I Gain", 82, 2, initial=0)
POSITION_P_GAIN = _r("Position P Gain", 84, 2)
FEEDFORWARD_2ND_GAIN = _r("Feedforward 2nd Gain", 88, 2, initial=0)
FEEDFORWARD_1ST_GAIN = _r("Feedforward 1st Gain", 90, 2, initial=0)
BUS_WATCHDOG = _r("Bus Watchdog", 98, 1, initial=0)
GOAL_PWM = _r("Goal PWM", 100, 2, signed=True)  # -PWM Limit ~ PWM Limit
GOAL_VELOCITY = _r("Goal Velocity", 104, 4, signed=True)  # -Velocity Limit ~ Velocity Limit
PROFILE_ACCELERATION = _r("Profile Acceleration", 108, 4, initial=0)
PROFILE_VELOCITY = _r("Profile Velocity", 112, 4, initial=0)
GOAL_POSITION = _r("Goal Position", 116, 4, signed=True)
REALTIME_TICK = _r("Realtime Tick", 120, 2, "R")
MOVING = _r("Moving", 122, 1, "R", initial=0)
MOVING_STATUS = _r("Moving Status", 123, 1, "R", initial=0)
PRESENT_PWM = _r("Present PWM", 124, 2, "R", signed=True)
PRESENT_VELOCITY = _r("Present Velocity", 128, 4, "R", signed=True)
PRESENT_POSITION = _r("Present Position", 132, 4, "R", signed=True)
VELOCITY_TRAJECTORY = _r("Velocity Trajectory", 136, 4, "R", signed=True)
POSITION_TRAJECTORY = _r("Position Trajectory", 140, 4, "R", signed=True)
PRESENT_INPUT_VOLTAGE = _r("Present Input Voltage", 144, 2, "R")
PRESENT_TEMPERATURE = _r("Present Temperature", 146, 1, "R")

# -- rows only some models have ------------------------------------------------------------
CURRENT_LIMIT = _e("Current Limit", 38, 2)  # XM430-W350 page; not on the XL430-W250 page
STARTUP_CONFIGURATION = _e("Startup Configuration", 60, 1, initial=0)  # XL430-W250 page
PWM_SLOPE = _e("PWM Slope", 62, 1)  # XL330-M288 (dynamixel_models)
EXTERNAL_PORT_MODES = tuple(_e(f"External Port Mode {n}", 55 + n, 1) for n in (1, 2, 3))  # XM540
GOAL_CURRENT = _r("Goal Current", 102, 2, signed=True)  # XM430-W350 page: -Current Limit ~
PRESENT_LOAD = _r("Present Load", 126, 2, "R", signed=True)  # XL430-W250 page: -1,000 ~ 1,000
PRESENT_CURRENT = _r("Present Current", 126, 2, "R", signed=True)  # XM430-W350 page
BACKUP_READY = _r("Backup Ready", 147, 1, "R")  # XL430-W250 page (not on the XM430 revision)


def _indirect() -> tuple[Item, ...]:
    """Indirect Address 1..56 (initial: the address of its Indirect Data) and Data 1..56, as
    both pages list them: 1..28 at 168/224, 29..56 at 578/634."""
    items: list[Item] = []
    for first, count, addr0, data0 in ((1, 28, 168, 224), (29, 28, 578, 634)):
        for k in range(count):
            items.append(_r(f"Indirect Address {first + k}", addr0 + 2 * k, 2, initial=data0 + k))
            items.append(_r(f"Indirect Data {first + k}", data0 + k, 1, initial=0))
    return tuple(items)


COMMON = (
    MODEL_NUMBER, MODEL_INFORMATION, FIRMWARE_VERSION, ID, BAUD_RATE, RETURN_DELAY_TIME,
    DRIVE_MODE, OPERATING_MODE, SECONDARY_ID, PROTOCOL_TYPE, HOMING_OFFSET, MOVING_THRESHOLD,
    TEMPERATURE_LIMIT, MAX_VOLTAGE_LIMIT, MIN_VOLTAGE_LIMIT, PWM_LIMIT, VELOCITY_LIMIT,
    MAX_POSITION_LIMIT, MIN_POSITION_LIMIT, SHUTDOWN,
    TORQUE_ENABLE, LED, STATUS_RETURN_LEVEL, REGISTERED_INSTRUCTION, HARDWARE_ERROR_STATUS,
    VELOCITY_I_GAIN, VELOCITY_P_GAIN, POSITION_D_GAIN, POSITION_I_GAIN, POSITION_P_GAIN,
    FEEDFORWARD_2ND_GAIN, FEEDFORWARD_1ST_GAIN, BUS_WATCHDOG, GOAL_PWM, GOAL_VELOCITY,
    PROFILE_ACCELERATION, PROFILE_VELOCITY, GOAL_POSITION, REALTIME_TICK, MOVING, MOVING_STATUS,
    PRESENT_PWM, PRESENT_VELOCITY, PRESENT_POSITION, VELOCITY_TRAJECTORY, POSITION_TRAJECTORY,
    PRESENT_INPUT_VOLTAGE, PRESENT_TEMPERATURE, *_indirect(),
)  # fmt: skip

#: Model Number (address 0) -> name, as each model's page gives it in its Model Number row
#: (the pages :mod:`rti_rig.simulator.dynamixel_models` cites).
MODEL_NAMES = {
    1060: "XL430-W250",
    1090: "2XL430-W250",
    1020: "XM430-W350",
    1030: "XM430-W210",
    1000: "XH430-W350",
    1120: "XM540-W270",
    1200: "XL330-M288",
}
#: Two axes in one body (the 2XL430-W250 page: "Each axis has it's own dedicated Control
#: Table"; its EEPROM is writable only with every axis's torque off).
DUAL_AXIS_MODELS = frozenset({1090})

_LOAD = (PRESENT_LOAD, BACKUP_READY)
_CURRENT = (CURRENT_LIMIT, GOAL_CURRENT, PRESENT_CURRENT)
_EXTRA: dict[int, tuple[Item, ...]] = {
    1060: (*_LOAD, STARTUP_CONFIGURATION),
    1090: (PRESENT_LOAD,),
    1020: _CURRENT,
    1030: (*_CURRENT, STARTUP_CONFIGURATION),
    1000: (*_CURRENT, STARTUP_CONFIGURATION),
    1120: (*_CURRENT, STARTUP_CONFIGURATION, *EXTERNAL_PORT_MODES),
    1200: (*_CURRENT, STARTUP_CONFIGURATION, PWM_SLOPE),
}


def control_table(model_number: int) -> tuple[Item, ...]:
    """Every item of ``model_number``'s table, by address (KeyError names the known models)."""
    try:
        extra = _EXTRA[model_number]
    except KeyError:
        known = ", ".join(f"{n} ({name})" for n, name in MODEL_NAMES.items())
        raise KeyError(
            f"no control table for model number {model_number}; known: {known}"
        ) from None
    model = replace(MODEL_NUMBER, initial=model_number)
    items = (model, *(i for i in COMMON if i is not MODEL_NUMBER), *extra)
    return tuple(sorted(items, key=lambda i: i.address))


#: One past the last address (Indirect Data 56, 661).
TABLE_SIZE = 662
#: Addresses below this are the EEPROM area (both pages: EEPROM 0..63, RAM from 64).
EEPROM_END = TORQUE_ENABLE.address

#: Baud Rate (8) code -> bits per second.
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

#: Hardware Error Status (70) / Shutdown (63) bits, X branch of the Shutdown include.
INPUT_VOLTAGE_ERROR = 0x01
OVERHEATING_ERROR = 0x04
MOTOR_ENCODER_ERROR = 0x08
ELECTRICAL_SHOCK_ERROR = 0x10
OVERLOAD_ERROR = 0x20

#: Operating Mode (11) values: Position Control (one turn, the position limits enforced) and
#: Extended Position Control (multi-turn, -256 .. 256 rev, the limits not used).
POSITION_MODE = 3
EXTENDED_POSITION_MODE = 4
EXTENDED_TICK_LIMIT = 256 * 4096 - 1
#: Drive Mode (10) bits: 2 time-based profile; 3 Torque On by Goal Update (firmware 45+).
DRIVE_MODE_TIME_BASED_PROFILE = 0x04

#: Units of the tables' Unit column.
TICKS_PER_REV = 4096
RPM_PER_VELOCITY_UNIT = 0.229
REV_MIN2_PER_ACCEL_UNIT = 214.577
