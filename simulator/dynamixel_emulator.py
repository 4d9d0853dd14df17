"""Dynamixel Protocol 2.0 X-series servos, emulated byte for byte, so that the official
``dynamixel_sdk`` runs unchanged against them (over a pty or an in-process port).

What is modelled: the control table as bytes, starting from each model's factory table as the
ROBOTIS e-manual publishes it (:mod:`rti_rig.simulator.dynamixel_table`, its registers and
Initial Values, and :mod:`rti_rig.simulator.dynamixel_models`, cited per model: the XL330's
Shutdown 0x35, Velocity Limits, voltage limits, ...); EEPROM locked while torque is on,
read-only registers, position limits in position mode, Profile Velocity refused above the
Velocity Limit (Data Limit Error), the supply checked against the Min/Max Voltage Limit,
Operating Mode changes resetting the profile; Ping/Read/Write/Reg Write/Action/Factory
Reset/Reboot/Clear/Sync Read/Sync Write/Bulk Read/Bulk Write, Status Return Level, the Alert
bit, motion under Profile Velocity/Acceleration (trapezoid in *emulator time* read from an
injected clock, so a dry run with a ``VirtualClock`` never waits) and fault injection: hardware
errors (Alert in every status; torque off and motion frozen only for the errors the Shutdown
register selects, as the e-manual says), corrupted CRC on replies, and silent (disconnected)
servos, or a whole chain whose supply is lost (``power_lost``); a servo at another baud rate,
or switched to Protocol 1.0 (Protocol Type 13 = 1), answers nothing. A Hardware Error Status
bit stays set until a Reboot (not verified for a non-shutdown error whose cause has passed),
also between rti-rig commands: a rig's emulated chain is modelled as staying powered, each
servo's control table (torque, goal, RAM, EEPROM, latched errors) and resting pose kept in a
small state file (:mod:`rti_rig.simulator.servo_latch`, :meth:`EmulatedServo.powered_state`;
delete it to "power-cycle" the servos).

Deliberate simplifications: a new goal during a move restarts the profile from the present
position at zero velocity (the firmware blends); no load, current or temperature dynamics.
Return Delay Time is modelled by the pty server (:mod:`rti_rig.simulator.dynamixel_pty`): a
status reaches the rig's own host only once it listens, never in wall time; a plain
``PortHandler`` gets it after the servo's Return Delay Time (9) and its wire time. The rig's
own ports (in-process or on the pty) charge the clock with that time instead
(:mod:`rti_rig.simulator.dynamixel_bus_time`), so a dry run's session time includes the bus's.

Like a real servo, a unicast Action and unicast writes *are* answered; the SDK does not read
those replies (a pitfall the driver handles). The wire is read and written by
:mod:`rti_rig.simulator.dynamixel_wire`, from the e-manual's Protocol 2.0 page, never by the
driver's codec (a codec bug would otherwise be on both sides of the wire; an import-linter
contract forbids it): instruction packets are taken by Length, because the SDK sends them
unstuffed.
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any, NamedTuple

from rti_rig.core.clock import Clock
from rti_rig.core.shell_words import shown_path
from rti_rig.simulator import dynamixel_models as models
from rti_rig.simulator import dynamixel_table as tbl
from rti_rig.simulator import dynamixel_wire as wire
from rti_rig.simulator.dynamixel_bus_time import BusTime
from rti_rig.simulator.pty_link import HostBaudDevice

#: The registers a servo leaves the factory with, and the field of
#: :class:`~rti_rig.simulator.dynamixel_models.FactoryTable` that holds each one's value.
FACTORY_REGISTERS = (
    (tbl.BAUD_RATE, "baud_rate"),
    (tbl.RETURN_DELAY_TIME, "return_delay_time"),
    (tbl.DRIVE_MODE, "drive_mode"),
    (tbl.OPERATING_MODE, "operating_mode"),
    (tbl.SECONDARY_ID, "secondary_id"),
    (tbl.PROTOCOL_TYPE, "protocol_type"),
    (tbl.HOMING_OFFSET, "homing_offset"),
    (tbl.MOVING_THRESHOLD, "moving_threshold"),
    (tbl.TEMPERATURE_LIMIT, "temperature_limit"),
    (tbl.MAX_VOLTAGE_LIMIT, "max_voltage_limit"),
    (tbl.MIN_VOLTAGE_LIMIT, "min_voltage_limit"),
    (tbl.PWM_LIMIT, "pwm_limit"),
    (tbl.CURRENT_LIMIT, "current_limit"),
    (tbl.VELOCITY_LIMIT, "velocity_limit"),
    (tbl.MAX_POSITION_LIMIT, "max_position_limit"),
    (tbl.MIN_POSITION_LIMIT, "min_position_limit"),
    (tbl.SHUTDOWN, "shutdown"),
    (tbl.STATUS_RETURN_LEVEL, "status_return_level"),
)
DEFAULT_FIRMWARE = 46
#: Factory Reset (0x06) Param 1: reset all, all but the ID, all but the ID and the Baud Rate
FACTORY_RESET_OPTIONS = (0xFF, 0x01, 0x02)

#: A servo's own errors by the name ``[[emulator.faults]]`` gives them: their bits of Hardware
#: Error Status (70) (ROBOTIS e-manual, X-series control table).
HARDWARE_FAULT_BITS = {
    "overload": tbl.OVERLOAD_ERROR,
    "overheating": tbl.OVERHEATING_ERROR,
    "input_voltage": tbl.INPUT_VOLTAGE_ERROR,
    "electrical_shock": tbl.ELECTRICAL_SHOCK_ERROR,
}
#: Seconds a servo answers nothing after it acknowledged a Reboot instruction, while it
#: restarts. The e-manual (Protocol 2.0, Reboot) gives the status packet but no restart time;
#: measured on XC330 servos: the status comes at once, then ~0.4 s of silence
#: (ROBOTIS-GIT/emanual issue #1698, 2024-09-01, which also reports ROBOTIS's Arduino code
#: waiting 3 s).
RESTART_S = 0.4
#: Largest deviation from Goal Position (ticks) at which Moving Status says In-Position: the
#: e-manual's "predefined value" is not published for the X series, so this is an assumption.
IN_POSITION_TICKS = 1
#: Drive Mode (address 10) bit 3 and the firmware that brought it (ROBOTIS e-manual, X series).
TORQUE_ON_BY_GOAL_UPDATE = 0x08
TORQUE_ON_BY_GOAL_UPDATE_FIRMWARE = 45
#: Protocol Type (address 13) of a servo that speaks Protocol 2.0 (1: Protocol 1.0 only)
PROTOCOL_2 = 2


def _ticks_per_s(velocity_units: int) -> float:
    return velocity_units * tbl.RPM_PER_VELOCITY_UNIT / 60.0 * tbl.TICKS_PER_REV


def _ticks_per_s2(acceleration_units: int) -> float:
    return acceleration_units * tbl.REV_MIN2_PER_ACCEL_UNIT / 3600.0 * tbl.TICKS_PER_REV


@dataclass
class _Profile:
    """A trapezoidal (or triangular) move from ``start`` to ``goal`` beginning at ``t0``."""

    start: float
    goal: float
    t0: float
    v: float
    a: float

    def __post_init__(self) -> None:
        d = abs(self.goal - self.start)
        if math.isinf(self.a):
            self.ta, self.vp = 0.0, self.v
            self.total = d / self.v if self.v > 0 else 0.0
        elif d < self.v * self.v / self.a:  # never reaches the profile velocity
            self.ta = math.sqrt(d / self.a)
            self.vp = self.a * self.ta
            self.total = 2.0 * self.ta
        else:
            self.ta, self.vp = self.v / self.a, self.v
            self.total = d / self.v + self.ta

    def position(self, t: float) -> float:
        s = t - self.t0
        d = abs(self.goal - self.start)
        sign = 1.0 if self.goal >= self.start else -1.0
        if s <= 0:
            return self.start
        if s >= self.total:
            return self.goal
        if s < self.ta:
            x = 0.5 * self.a * s * s
        elif s <= self.total - self.ta:
            x = 0.5 * self.vp * self.ta + self.vp * (s - self.ta)
        else:
            r = self.total - s
            x = d - (0.5 * self.a * r * r if not math.isinf(self.a) else 0.0)
        return self.start + sign * min(x, d)

    def velocity(self, t: float) -> float:
        s = t - self.t0
        if s <= 0 or s >= self.total:
            return 0.0
        sign = 1.0 if self.goal >= self.start else -1.0
        if s < self.ta:
            return sign * self.a * s
        if s <= self.total - self.ta:
            return sign * self.vp
        return sign * self.a * (self.total - s)

    def moving(self, t: float) -> bool:
        return t - self.t0 < self.total


class EmulatedServo:
    """One X-series servo: a control table and a motion profile."""

    def __init__(
        self,
        dxl_id: int,
        model_number: int,
        clock: Clock,
        *,
        operating_mode: int = tbl.POSITION_MODE,
        present_ticks: int = 2048,
        min_position: int | None = None,
        max_position: int | None = None,
        firmware: int = DEFAULT_FIRMWARE,
        supply_decivolts: int | None = None,
    ) -> None:
        """A servo as it leaves the factory: the control table of ``model_number`` is the
        e-manual's Initial Values for that model (:mod:`rti_rig.simulator.dynamixel_models`,
        each cited), then ``dxl_id``, ``operating_mode`` and any position limits given.

        ``supply_decivolts`` is the bench supply (0.1 V), the model's recommended input voltage
        unless given; one outside the servo's voltage limits raises its Input Voltage Error as
        :meth:`set_input_voltage` describes."""
        self.clock = clock
        self.factory = models.factory_table(model_number)
        f = self.factory
        #: the model's control-table items (:mod:`rti_rig.simulator.dynamixel_table`), each
        #: written whole or not at all (Data Length Error otherwise): a Write may span several
        self.items = tbl.control_table(model_number)
        #: address ranges [start, end) of its read-only (Access R) items
        self.read_only = tuple(
            (i.address, i.address + i.size) for i in self.items if not i.writable
        )
        self.table = bytearray(tbl.TABLE_SIZE)
        for item in self.items:  # the table's Initial Values common to every model
            if item.initial is not None:
                self._set(item, item.initial)
        self._set(tbl.FIRMWARE_VERSION, firmware)
        self._set(tbl.ID, dxl_id)
        #: the ID this servo was built with (the config's): what its kept state is matched by
        #: when the next command builds the chain again, whatever ID its table holds by then
        self.built_id = dxl_id
        for reg, attr in FACTORY_REGISTERS:
            value = getattr(f, attr)
            if value is not None:  # None: the model lacks it (no Current Limit on an XL430)
                self._set(reg, value)
        for address, (size, value) in f.extra.items():
            self.table[address : address + size] = value.to_bytes(size, "little")
        # configured for the rig (Operating Mode and limits are EEPROM: set before delivery)
        self._set(tbl.OPERATING_MODE, int(operating_mode))
        if max_position is not None:
            self._set(tbl.MAX_POSITION_LIMIT, max_position)
        if min_position is not None:
            self._set(tbl.MIN_POSITION_LIMIT, min_position)
        self._set(tbl.PRESENT_TEMPERATURE, 30)
        self._set(tbl.GOAL_POSITION, present_ticks)
        self._profile = _Profile(present_ticks, present_ticks, clock.now(), 1.0, 1.0)
        #: True while the motion is the load's (a limp joint falling), not a profile's
        self._back_driven = False
        self._registered: tuple[int, bytes] | None = None
        self._shut_down = False
        #: how long a Reboot keeps it silent (:data:`RESTART_S`), and until when it is
        self.restart_s = RESTART_S
        self.restarting_until = float("-inf")
        #: the other axes of the same body (a 2XL430's second id): see :meth:`write`
        self.other_axes: list[EmulatedServo] = []
        #: Where a joint carrying a load falls to once its torque goes off (ticks; None: it
        #: stays where it is, as an unloaded joint does), and how fast (ticks/s): see
        #: :meth:`_go_limp`. Set on the arm's elevation joint by :func:`emulator_for_arm`.
        self.sag_to: float | None = None
        self.sag_ticks_per_s = 0.0
        #: the writable RAM area (Torque Enable .. Goal Position) as at power-on, restored by a
        #: Reboot (:meth:`reboot`)
        self._ram_at_power_on = bytes(self.table[tbl.EEPROM_END : tbl.REALTIME_TICK.address])
        self.set_input_voltage(
            f.recommended_supply_decivolts if supply_decivolts is None else supply_decivolts
        )

    # -- table helpers ----------------------------------------------------------------------
    def _set(self, reg: tbl.Item, value: int) -> None:
        raw = int(value) & ((1 << (8 * reg.size)) - 1)
        self.table[reg.address : reg.address + reg.size] = raw.to_bytes(reg.size, "little")

    def get(self, reg: tbl.Item) -> int:
        raw = int.from_bytes(self.table[reg.address : reg.address + reg.size], "little")
        return wire.signed(raw, reg.size) if reg.signed else raw

    @property
    def dxl_id(self) -> int:
        return self.table[tbl.ID.address]

    @property
    def torque_on(self) -> bool:
        return self.table[tbl.TORQUE_ENABLE.address] == 1

    @property
    def hardware_error(self) -> int:
        return self.table[tbl.HARDWARE_ERROR_STATUS.address]

    def position(self, now: float | None = None) -> float:
        """Present position in ticks (float) at emulator time ``now``."""
        return self._profile.position(self.clock.now() if now is None else now)

    def is_moving(self, now: float | None = None) -> bool:
        return self._profile.moving(self.clock.now() if now is None else now)

    def _refresh(self) -> None:
        now = self.clock.now()
        # a profile is one the servo runs towards its Goal Position; a limp joint falling
        # under its load (:meth:`_go_limp`) moves, but runs no profile
        profile = self._profile.moving(now) and not self._back_driven
        present = round(self._profile.position(now))
        self._set(tbl.PRESENT_POSITION, present)
        units = round(
            self._profile.velocity(now) / (tbl.RPM_PER_VELOCITY_UNIT / 60 * tbl.TICKS_PER_REV)
        )
        self._set(tbl.PRESENT_VELOCITY, units)
        # e-manual, Moving (122): set when |Present Velocity| exceeds Moving Threshold (24),
        # and always while a profile is in progress after a Goal Position update
        # (ROBOTIS-GIT/emanual _includes/en/dxl/x/moving.md @ d45c8b26). It had been the
        # emulator's motion alone, so a joint sagging with its torque off, slower than the
        # threshold, read Moving = 1 and "profile ongoing", which no servo reports.
        moving = profile or abs(units) > self.get(tbl.MOVING_THRESHOLD)
        self._set(tbl.MOVING, 1 if moving else 0)
        # e-manual, Moving Status (123): bit 1 "Profile Ongoing", bit 0 "In-Position: Whether
        # or not the DYNAMIXEL has arrived to the desired Goal Position(116)", set "when the
        # positional deviation is smaller than a predefined value" (ROBOTIS-GIT/emanual
        # _includes/en/dxl/x/moving_status.md @ 53247968642942cbbdb3fb52e47d5aef4269267a). A
        # servo stopped short of its goal (shut down by a fault mid-move, torque switched off)
        # has not arrived: In-Position had been set whenever no profile ran. The predefined
        # deviation is not published for the X series: IN_POSITION_TICKS is assumed. The
        # velocity-profile bits (4-5) are not modelled.
        arrived = not moving and abs(present - self.get(tbl.GOAL_POSITION)) <= IN_POSITION_TICKS
        self._set(tbl.MOVING_STATUS, (0x02 if profile else 0) | (0x01 if arrived else 0))
        self._set(tbl.REALTIME_TICK, int(now * 1000) % 32768)

    def _freeze(self) -> None:
        now = self.clock.now()
        p = self._profile.position(now)
        self._profile = _Profile(p, p, now, 1.0, 1.0)
        self._back_driven = False

    def _go_limp(self) -> None:
        """Torque just went off: a loaded joint (:attr:`sag_to`) falls towards its rest at
        :attr:`sag_ticks_per_s`, from where it is; an unloaded one stays put.

        Why: a servo whose torque is off is back-driven by its load (ROBOTIS e-manual, Torque
        Enable (64): with torque off the horn turns freely by an external force), and the
        emulated arm had frozen where it was, so a sag under an overload (Shutdown (63): torque
        off) was never seen through ``run``. The fall is modelled at a constant rate (gear
        friction, no inertia), an assumption, not a measurement."""
        self._freeze()
        if self.sag_to is None or self.sag_ticks_per_s <= 0:
            return
        now = self.clock.now()
        p = self._profile.position(now)
        self._profile = _Profile(p, self.sag_to, now, self.sag_ticks_per_s, math.inf)
        self._back_driven = True

    # -- faults -----------------------------------------------------------------------------
    @property
    def shut_down(self) -> bool:
        """True after a fault the Shutdown register selects, until a Reboot."""
        return self._shut_down

    def inject_hardware_error(self, bits: int) -> None:
        """Set Hardware Error Status bits; shut down only for the bits Shutdown selects.

        e-manual, X-series control table: Max/Min Voltage Limit (32/34) — "Input Voltage Error
        Bit(0x01) and Hardware Error Bit(0x80) in the Hardware Error Status(70) are set. If
        Input Voltage Error Bit is configured in the Shutdown(63), Torque Enable(64) is cleared";
        Temperature Limit (31) says the same of overheating; Shutdown (63): "REBOOT is the only
        method to reset Torque Enable(64) to '1' after the shutdown". So an error sets its bit
        and the Alert flag of every status packet, and only a bit Shutdown selects clears
        Torque Enable (motion stops; then only a Reboot lets torque back on). The factory
        Shutdown is the model's (:mod:`rti_rig.simulator.dynamixel_models`): 0x34 on the
        XL430/2XL430/XM430/XH430/XM540, which does not select an input-voltage error, and 0x35
        on the XL330-M288, which does (e-manual ``docs/en/dxl/x/xl330-m288.md``, Shutdown
        Initial Value 53; the Shutdown include marks its Input Voltage Error "(default)")."""
        bits &= 0xFF
        self.table[tbl.HARDWARE_ERROR_STATUS.address] |= bits
        if bits & self.get(tbl.SHUTDOWN):
            self._shut_down = True
            was_on = self.torque_on
            self._freeze()
            self.table[tbl.TORQUE_ENABLE.address] = 0
            if was_on:
                self._go_limp()

    def set_input_voltage(self, decivolts: int) -> None:
        """The supply the servo sees (Present Input Voltage, 0.1 V).

        e-manual, Min/Max Voltage Limit (32/34): when Present Input Voltage(144) exceeds the
        range of Max Voltage Limit(32) and Min Voltage Limit(34), the Input Voltage Error bit
        is set (and Torque Enable cleared if Shutdown selects it): here through
        :meth:`inject_hardware_error`. A supply back inside the limits clears nothing (the bit
        stays until a Reboot; not verified for a passed cause, as the module docstring says)."""
        self._set(tbl.PRESENT_INPUT_VOLTAGE, decivolts)
        if not self.get(tbl.MIN_VOLTAGE_LIMIT) <= decivolts <= self.get(tbl.MAX_VOLTAGE_LIMIT):
            self.inject_hardware_error(tbl.INPUT_VOLTAGE_ERROR)

    def reboot(self) -> None:
        """A restart, as at power-on: the RAM area back to its initial values, EEPROM kept.

        e-manual, X-series control table, Area: "Data in the RAM Area is reset to initial
        values when the power is reset"; the Shutdown notes give the S/W REBOOT (the Reboot
        instruction) beside turning the power off and on (ROBOTIS-GIT/emanual
        _includes/en/dxl/x/control_table.md @ add0d1dabec2202f8ae9848b7eda8e98f9a44b0f,
        shutdown.md @ 048ec0de57bc856b9f127ef854243fb44c86d428). So Profile Velocity and
        Acceleration, LED, Status Return Level, a registered instruction and the Hardware Error
        Status go back to their initial values, not only the error and torque (a reboot had
        kept the session's profile and the LED: a driver that relied on them after a reboot
        would have passed here and failed on a servo). The initial Goal Position is not given
        ("-"): the present position is modelled, as for a torque-on. A supply still outside
        the voltage limits raises its error again."""
        self._shut_down = False
        was_on = self.torque_on
        if was_on:
            self._freeze()  # a limp joint's motion is its load's: a reboot does not stop it
        # it answers nothing while it restarts (the Reboot's own status went out first)
        self.restarting_until = self.clock.now() + self.restart_s
        self.table[tbl.EEPROM_END : tbl.REALTIME_TICK.address] = self._ram_at_power_on
        self._set(tbl.GOAL_POSITION, round(self.position()))
        self._registered = None
        # a supply still outside the limits is met again by the restarted servo
        self.set_input_voltage(self.get(tbl.PRESENT_INPUT_VOLTAGE))
        if was_on and not self.torque_on:
            self._go_limp()  # a reboot under torque drops the joint it held

    # -- kept while powered -----------------------------------------------------------------
    def powered_state(self) -> dict[str, Any]:
        """What this servo keeps while it stays powered, for the next command on the rig
        (:mod:`rti_rig.simulator.servo_latch`): its whole control table (the EEPROM area and
        the RAM area: Torque Enable, Goal Position, profiles, LED, Status Return Level,
        Hardware Error Status), a shutdown, a registered instruction, and where the joint
        comes to rest.

        Why the rest, not the present position: between two commands a servo with torque on
        runs its profile to its Goal Position, and a limp loaded joint falls to its stop, so
        the next command finds it at the end of its motion (ROBOTIS e-manual, Torque Enable
        (64); RAM "reset to initial values when the power is reset", and only then)."""
        self._refresh()
        rest = self._profile.goal
        table = bytearray(self.table)
        table[tbl.PRESENT_POSITION.address : tbl.PRESENT_POSITION.address + 4] = (
            round(rest) & 0xFFFFFFFF
        ).to_bytes(4, "little")
        return {
            "built_id": self.built_id,
            "model_number": self.get(tbl.MODEL_NUMBER),
            "table": table.hex(),
            "rest_ticks": rest,
            "shut_down": self._shut_down,
            "registered": None
            if self._registered is None
            else [self._registered[0], self._registered[1].hex()],
        }

    def restore_powered(self, state: dict[str, Any]) -> bool:
        """Take up a :meth:`powered_state` an earlier command left (the servo never lost
        power); False, nothing changed, for one that is not this servo's (another model, a
        damaged record): that chain is met as at power-on."""
        try:
            table = bytes.fromhex(str(state["table"]))
            rest = float(state["rest_ticks"])
            model = int(state["model_number"])
            registered = state.get("registered")
            reg = (
                None
                if registered is None
                else (int(registered[0]), bytes.fromhex(str(registered[1])))
            )
        except (KeyError, TypeError, ValueError, IndexError):
            return False
        if len(table) != tbl.TABLE_SIZE or model != self.get(tbl.MODEL_NUMBER):
            return False
        if not self._is_mine(state, table[tbl.ID.address]):
            return False
        if not math.isfinite(rest):
            return False
        self.table[:] = table
        self._profile = _Profile(rest, rest, self.clock.now(), 1.0, 1.0)
        self._back_driven = False
        self._shut_down = bool(state.get("shut_down", False))
        self._registered = reg
        self._refresh()
        return True

    def _is_mine(self, state: dict[str, Any], kept_id: int) -> bool:
        """Whether a kept record is this servo's: the one built with the same ID (the ID its
        table then held, ``kept_id``, may differ: an ID written, a Factory Reset to 1, kept as
        the EEPROM keeps it); a record from before ``built_id`` was kept, by that ID alone."""
        built = state.get("built_id")
        try:
            return int(built) == self.built_id if built is not None else kept_id == self.dxl_id
        except (TypeError, ValueError):
            return False

    def eeprom_state(self) -> dict[str, Any]:
        """What this servo keeps through a power cycle: its EEPROM area (ID, baud rate,
        Operating Mode, the position limits a connect wrote, ...) and where the joint rests
        once unpowered: a loaded joint that held under torque falls to its stop
        (:attr:`sag_to`), any other stays where it is.

        Why apart from :meth:`powered_state`: the e-manual's RAM area is "reset to initial
        values when the power is reset", the EEPROM area is not (X-series control table,
        Area); the chain's power cycle had been the deletion of one state file holding both,
        so it also reset the EEPROM and moved the joints back to the park pose, which a real
        power cycle does not."""
        self._refresh()
        rest = self._profile.goal
        if self.torque_on and self.sag_to is not None:
            rest = self.sag_to
        return {
            "built_id": self.built_id,
            "model_number": self.get(tbl.MODEL_NUMBER),
            "eeprom": bytes(self.table[: tbl.EEPROM_END]).hex(),
            "rest_ticks": rest,
        }

    def restore_eeprom(self, state: dict[str, Any]) -> bool:
        """Power on with an :meth:`eeprom_state` kept from before the power cycle: the EEPROM
        area as it was, the RAM area at its initial values (as built), the joint where it
        rested. False, nothing changed, for a record that is not this servo's."""
        try:
            eeprom = bytes.fromhex(str(state["eeprom"]))
            rest = float(state["rest_ticks"])
            model = int(state["model_number"])
        except (KeyError, TypeError, ValueError):
            return False
        if len(eeprom) != tbl.EEPROM_END or model != self.get(tbl.MODEL_NUMBER):
            return False
        if not self._is_mine(state, eeprom[tbl.ID.address]) or not math.isfinite(rest):
            return False
        self.table[: tbl.EEPROM_END] = eeprom
        self._profile = _Profile(rest, rest, self.clock.now(), 1.0, 1.0)
        self._back_driven = False
        self._set(tbl.GOAL_POSITION, round(rest))
        self._refresh()
        return True

    # -- instructions -----------------------------------------------------------------------
    def status_error(self, number: int = 0) -> int:
        return number | (wire.ALERT if self.hardware_error else 0)

    def read(self, address: int, length: int) -> tuple[int, bytes]:
        if length < 0 or address + length > tbl.TABLE_SIZE:
            return wire.DATA_LENGTH_ERROR, b""
        self._refresh()
        return 0, bytes(self.table[address : address + length])

    def write(self, address: int, data: bytes) -> int:
        """Apply a Write; returns the error number (0 = ok).

        A Write sets consecutive bytes from its start address, so one packet may cover several
        items (Profile Acceleration, Profile Velocity and Goal Position, 108..119, say); an item
        it covers only in part is refused with a Data Length Error, which the e-manual defines
        as "Attempt to write Data that is shorter than the data length of the corresponding
        Address (ex: when you attempt to only use 2 bytes of a item that has been defined as 4
        bytes)" (Protocol 2.0, Status Packet, Error; ROBOTIS-GIT/emanual
        docs/en/dxl/protocol2.md @ 01179568a085cfc99bdad6e880e43fa871bd318a). Every check runs
        before any byte is written: a refused Write changes nothing. (The emulator had refused
        any Write that did not hold the Goal Position alone, and accepted half of any other
        item: it modelled the packets our driver sends, not the servo.)"""
        end = address + len(data)
        if not data or end > tbl.TABLE_SIZE:
            return wire.DATA_LENGTH_ERROR
        for lo, hi in self.read_only:
            if address < hi and end > lo:
                return wire.ACCESS_ERROR
        if address < tbl.EEPROM_END and (
            self.torque_on or any(axis.torque_on for axis in self.other_axes)
        ):
            # a two-axis body (2XL430) locks its EEPROM while either axis has torque on
            # (tbl.DUAL_AXIS_MODELS: "for all axis are set to '0'")
            return wire.ACCESS_ERROR
        for reg in self.items:
            covers_some = address < reg.address + reg.size and end > reg.address
            if covers_some and not address <= reg.address <= reg.address + reg.size <= end:
                return wire.DATA_LENGTH_ERROR

        def covered(reg: tbl.Item) -> bytes | None:
            """The bytes this Write gives ``reg``, if it covers it."""
            if address <= reg.address and reg.address + reg.size <= end:
                return data[reg.address - address : reg.address - address + reg.size]
            return None

        goal_bytes = covered(tbl.GOAL_POSITION)
        goal: int | None = None
        if goal_bytes is not None:
            goal = wire.signed(int.from_bytes(goal_bytes, "little"), 4)
            if self.get(tbl.OPERATING_MODE) == tbl.POSITION_MODE:
                lo, hi = self.get(tbl.MIN_POSITION_LIMIT), self.get(tbl.MAX_POSITION_LIMIT)
            else:
                lo, hi = -tbl.EXTENDED_TICK_LIMIT, tbl.EXTENDED_TICK_LIMIT
            # e-manual, Min/Max Position Limit (48, 52): "Provided Goal Position(116) values
            # must be within the configured position limit range" (ROBOTIS-GIT/emanual
            # _includes/en/dxl/x/position_limit.md @ f9dea50c); an XL430 given a goal outside
            # them does nothing at all, it is not clamped onto the limit (ROBOTIS forum,
            # "Position limit in joint mode", forum.robotis.com/t/452): refused, nothing moves
            if not lo <= goal <= hi:
                return wire.DATA_LIMIT_ERROR
        torque_bytes = covered(tbl.TORQUE_ENABLE)
        if torque_bytes is not None and torque_bytes[0] and self._shut_down:
            return wire.RESULT_FAIL  # after a shutdown only a reboot re-enables torque
        pv_bytes = covered(tbl.PROFILE_VELOCITY)
        time_based = self.get(tbl.DRIVE_MODE) & tbl.DRIVE_MODE_TIME_BASED_PROFILE
        # e-manual, Velocity Limit(44): "maximum velocity of Goal Velocity(104) and Profile
        # Velocity(112)"; the control-table include adds "Values for Goal Velocity and
        # Profile Velocity cannot be set to values exceeding the Velocity Limit ... Data
        # Limit Error" (ROBOTIS-GIT/emanual _includes/en/dxl/control_table/velocity_limit.md
        # @ 9344769ede3e0f19f4e4d876e3e80639f3188ae9, an include with Y-series branches; the
        # X pages' own include, control_table_vellimit.md, says only "maximum velocity").
        # Refused or capped on an X-series servo is NOT verified (a dynamixel-workbench
        # issue, #207, reads as capped): refusing is modelled, the stricter case, and the
        # driver checks the limit before writing, so it meets neither
        if (
            pv_bytes is not None
            and not time_based
            and int.from_bytes(pv_bytes, "little") > self.get(tbl.VELOCITY_LIMIT)
        ):
            return wire.DATA_LIMIT_ERROR
        # every check passed: the Write takes effect
        limp = torque_bytes is not None and not torque_bytes[0] and self.torque_on
        if torque_bytes is not None:
            if not torque_bytes[0]:
                if self.torque_on:  # a limp joint's motion is its load's: not stopped here
                    self._freeze()
            elif not self.torque_on:
                # modelled: torque-on holds the present position (goal := present). Not
                # verified against the e-manual; the driver writes goal := present first anyway
                self._freeze()
                self._set(tbl.GOAL_POSITION, round(self.position()))
        mode_before = self.get(tbl.OPERATING_MODE)
        self.table[address:end] = data
        if limp:
            self._go_limp()
        if self.get(tbl.OPERATING_MODE) != mode_before:
            self._set(tbl.PROFILE_VELOCITY, 0)
            self._set(tbl.PROFILE_ACCELERATION, 0)
        if goal is not None:
            if (
                not self.torque_on
                and not self._shut_down
                and self.get(tbl.DRIVE_MODE) & TORQUE_ON_BY_GOAL_UPDATE
                and self.get(tbl.FIRMWARE_VERSION) >= TORQUE_ON_BY_GOAL_UPDATE_FIRMWARE
            ):
                # e-manual, Drive Mode bit 3 "Torque On by Goal Update" (firmware 45+): a goal
                # written while Torque Enable is 0 switches torque on, and the servo moves to it
                self.table[tbl.TORQUE_ENABLE.address] = 1
            self._start_move(goal)  # with the profile this Write may have set too
        return 0

    def _start_move(self, goal: int) -> None:
        if not self.torque_on:
            return
        now = self.clock.now()
        v_units = self.get(tbl.PROFILE_VELOCITY) or self.get(tbl.VELOCITY_LIMIT) or 1
        a_units = self.get(tbl.PROFILE_ACCELERATION)
        a = _ticks_per_s2(a_units) if a_units else math.inf
        self._profile = _Profile(
            self._profile.position(now), float(goal), now, _ticks_per_s(v_units), a
        )
        self._back_driven = False

    def reg_write(self, address: int, data: bytes) -> int:
        self._registered = (address, bytes(data))
        self.table[tbl.REGISTERED_INSTRUCTION.address] = 1
        return 0

    def action(self) -> int:
        if self._registered is None:
            return wire.INSTRUCTION_ERROR
        address, data = self._registered
        self._registered = None
        self.table[tbl.REGISTERED_INSTRUCTION.address] = 0
        return self.write(address, data)

    def clear_multi_turn(self) -> int:
        if self.is_moving():
            return wire.RESULT_FAIL
        p = round(self.position()) % tbl.TICKS_PER_REV
        self._profile = _Profile(p, p, self.clock.now(), 1.0, 1.0)
        self._back_driven = False
        self._set(tbl.GOAL_POSITION, p)
        return 0

    def factory_reset(self, option: int) -> None:
        """The Factory Reset instruction (0x06): the control table back to the model's
        factory Initial Values, then a restart; ``option`` 0xFF resets everything, 0x01 all
        but the ID, 0x02 all but the ID and the Baud Rate.

        e-manual, Protocol 2.0, Factory Reset: "Instruction that resets the Control Table to
        its initial factory default settings", "a device is rebooted", Param 1 "0xFF : Reset
        all 0x01 : Reset all except ID 0x02 : Reset all except ID and Baudrate"
        (ROBOTIS-GIT/emanual docs/en/dxl/protocol2.md @
        01179568a085cfc99bdad6e880e43fa871bd318a). So the rig's configuration goes too: the
        Operating Mode and the position limits a connect wrote are the factory's again (3 and
        0..4,095), as on a real servo; the Firmware Version, not a setting, stays. The caller
        (:meth:`DynamixelBusEmulator._execute`) refuses 0xFF sent to the broadcast ID, as the
        page says. Why: the emulator had answered it with an Instruction Error, which no X
        servo (firmware 42 and later) does, so a tool that resets a servo could not be tried."""
        fresh = EmulatedServo(
            self.dxl_id if option in (0x01, 0x02) else tbl.ID.initial or 1,
            self.get(tbl.MODEL_NUMBER),
            self.clock,
            present_ticks=round(self.position()),
            firmware=self.get(tbl.FIRMWARE_VERSION),
            supply_decivolts=self.get(tbl.PRESENT_INPUT_VOLTAGE),
        )
        eeprom = bytearray(fresh.table[: tbl.EEPROM_END])
        if option == 0x02:
            eeprom[tbl.BAUD_RATE.address] = self.table[tbl.BAUD_RATE.address]
        self.table[: tbl.EEPROM_END] = eeprom
        self._ram_at_power_on = fresh._ram_at_power_on
        self.reboot()


class DynamixelBusEmulator(HostBaudDevice):
    """Several servos on one bus: bytes in, status bytes out (thread-safe).

    Declares :class:`~rti_rig.simulator.pty_link.HostBaudDevice`: it hears the host's line
    speed (``host_baud``), which the pty server sets only on a device that declares it (the
    server had set the attribute undeclared, unseen by the protocol check).

    Fault injection: ``silent_ids`` never answer nor act (a disconnected servo);
    ``corrupt_next_replies`` damages the CRC of that many upcoming status packets;
    ``drop_next_replies`` loses that many upcoming status packets on the wire (the servo acted
    on the instruction, the host hears nothing: the SDK's COMM_RX_TIMEOUT); ``reply_faults``
    does either to the status of the K-th instruction packet received (1 = the first, any id):
    ``{K: "drop_reply" | "garble_reply"}``, the rig config's ``[[emulator.faults]]``;
    ``hardware_faults`` raises a servo's own error as the K-th instruction packet arrives:
    ``{K: (servo id, "overload" | "overheating" | "input_voltage" | "electrical_shock")}``
    (:meth:`EmulatedServo.inject_hardware_error`: the Alert bit until a Reboot, torque off
    for the faults the servo's Shutdown selects).
    ``goal_log`` records every Goal Position value that reached the bus, accepted or not.
    """

    def __init__(self, servos: Iterable[EmulatedServo], clock: Clock) -> None:
        #: every servo on the bus, in chain order, whatever its ID: two may share one (an ID
        #: written to another's, a Factory Reset to ID 1), and both hear and answer it
        self.chain: list[EmulatedServo] = list(servos)
        #: the servos by their ID (Control Table ID (7)) as it is now: the first in the chain
        #: of any that share one (:meth:`_rekey`); one dict for the emulator's lifetime, held
        #: by the ports' bus time
        self.servos: dict[int, EmulatedServo] = {}
        self._rekey()
        self.clock = clock
        self.silent_ids: set[int] = set()
        #: The host's line speed, where the transport knows it (set with the port's baud
        #: rate). A servo whose Baud Rate (address 8) is another speed sees framing noise and
        #: answers nothing, as a real one does: a config with the wrong baud rate fails here
        #: as on the rig (it had passed `check`).
        self.host_baud: int | None = None
        #: the servos that hear nothing of the packets being handled
        self._deaf: set[EmulatedServo] = set()
        self.corrupt_next_replies = 0
        self.drop_next_replies = 0
        self.reply_faults: dict[int, str] = {}
        #: ``delay_reply`` faults: the K-th packet's status, late by this many seconds
        self.reply_delays: dict[int, float] = {}
        #: statuses on their way late (``delay_reply``): ``(delay s, bytes)``, delivered by
        #: the port after the host's reply window if it is shorter (:meth:`take_late`)
        self.late: list[tuple[float, bytes]] = []
        self.hardware_faults: dict[int, list[tuple[int, str]]] = {}
        #: ``power_lost``: from this instruction packet on (1 = the first), the chain's supply
        #: is gone: no servo hears, acts or answers (ROBOTIS e-manual: an unpowered servo is
        #: simply absent from the bus); None: powered throughout
        self.power_lost_at: int | None = None
        #: instruction packets received so far (what ``reply_faults`` counts)
        self.instructions_received = 0
        self.goal_log: list[tuple[int, int]] = []
        self.instructions: list[wire.Instruction] = []
        self._parser = wire.InstructionReader()
        self._lock = threading.RLock()
        #: Called with every servo's Hardware Error Status (id -> bits) whenever one changes:
        #: one moment the chain's powered state is kept, to outlive the command
        #: (:mod:`rti_rig.simulator.servo_latch`). None: nothing outlives the emulator.
        self.on_errors_changed: Callable[[dict[int, int]], None] | None = None
        self._errors_seen = self.hardware_errors()

    # -- accessors for the simulated rig ----------------------------------------------------
    def joint_positions(self) -> dict[int, float]:
        """Present position (ticks, float) of every servo at the clock's current time."""
        with self._lock:
            return {i: s.position() for i, s in self.servos.items()}

    def hardware_errors(self) -> dict[int, int]:
        """Every servo's Hardware Error Status (70) bits, by id."""
        with self._lock:
            return {i: s.hardware_error for i, s in self.servos.items()}

    def _errors_changed(self) -> None:
        """Tell :attr:`on_errors_changed` of a change in any servo's Hardware Error Status."""
        now = self.hardware_errors()
        if now != self._errors_seen:
            self._errors_seen = now
            if self.on_errors_changed is not None:
                self.on_errors_changed(now)

    def powered_state(self) -> dict[int, dict[str, Any]]:
        """Every servo's :meth:`EmulatedServo.powered_state`, by its place in the chain.

        Why by place, not ID: two servos may share an ID (one written to another's, a Factory
        Reset to 1), and a map by ID had kept the first alone: the second's state was lost."""
        with self._lock:
            return {place: s.powered_state() for place, s in enumerate(self.chain)}

    def restore_powered(self, states: dict[int, dict[str, Any]]) -> None:
        """Give each servo the state an earlier command left it (see
        :meth:`EmulatedServo.restore_powered`); one not on this bus is left alone."""
        with self._lock:
            for key, state in states.items():
                servo = self._kept_servo(key, state)
                if servo is not None:
                    servo.restore_powered(state)
            self._rekey()  # an ID kept as changed is where the servo answers
            self._errors_seen = self.hardware_errors()

    def eeprom_state(self) -> dict[int, dict[str, Any]]:
        """Every servo's :meth:`EmulatedServo.eeprom_state`, by its place in the chain (see
        :meth:`powered_state`)."""
        with self._lock:
            return {place: s.eeprom_state() for place, s in enumerate(self.chain)}

    def restore_eeprom(self, states: dict[int, dict[str, Any]]) -> None:
        """Power the chain on with the EEPROM each servo kept through a power cycle (see
        :meth:`EmulatedServo.restore_eeprom`); one not on this bus is left alone."""
        with self._lock:
            for key, state in states.items():
                servo = self._kept_servo(key, state)
                if servo is not None:
                    servo.restore_eeprom(state)
            self._rekey()

    def _kept_servo(self, key: int, state: dict[str, Any]) -> EmulatedServo | None:
        """The servo a kept record is for: the chain's ``key``-th (a record with its
        ``built_id``), else, a record kept by ID before, the servo at ID ``key``."""
        if "built_id" in state:
            return self.chain[key] if 0 <= key < len(self.chain) else None
        return self.servos.get(key)

    def inject_hardware_error(self, dxl_id: int, fault: int) -> None:
        with self._lock:
            self.servos[dxl_id].inject_hardware_error(int(fault))
            self._errors_changed()

    def set_input_voltage(self, dxl_id: int, decivolts: int) -> None:
        """The supply servo ``dxl_id`` sees (0.1 V); outside its limits: Input Voltage Error."""
        with self._lock:
            self.servos[dxl_id].set_input_voltage(int(decivolts))
            self._errors_changed()

    # -- bytes ------------------------------------------------------------------------------
    def receive(self, data: bytes) -> bytes:
        """Feed instruction bytes; return the status bytes the servos send back."""
        with self._lock:
            # a servo whose Protocol Type (13) is not 2 speaks Protocol 1.0 only (ROBOTIS
            # e-manual, Protocol Compatibility Table: "X-series can switch DYNAMIXEL Protocol
            # 2.0 into DYNAMIXEL Protocol 1.0 ... Protocol Type(13)") and does not answer these
            # packets: it had answered them, so a servo set to 1.0 passed `check` here
            now = self.clock.now()
            self._deaf = {
                servo
                for servo in self.chain
                if servo.dxl_id in self.silent_ids
                or now < servo.restarting_until  # restarting after a Reboot
                or (
                    self.host_baud is not None
                    and tbl.BAUD_CODES.get(servo.get(tbl.BAUD_RATE)) != self.host_baud
                )
                or servo.get(tbl.PROTOCOL_TYPE) != PROTOCOL_2
                or self._unpowered(self.instructions_received + 1)
            }
            self._parser.feed(bytes(data))
            out = bytearray()
            for item in self._parser.packets():
                if isinstance(item, wire.BadCrc):
                    out += self._at_once(
                        [
                            self._reply(s.dxl_id, wire.CRC_ERROR, servo=s)
                            for s in self._on(item.raw[4])
                        ]
                    )
                    continue
                self.instructions.append(item)
                self.instructions_received += 1
                if self._unpowered(self.instructions_received):
                    self._deaf = set(self.chain)  # this packet and every later one unheard
                for dxl_id, kind in self.hardware_faults.get(self.instructions_received, ()):
                    if dxl_id in self.servos:
                        # the servo's own error, as it meets it (an overload under load): its
                        # bit, the Alert flag from this status on, torque off if Shutdown says
                        self.servos[dxl_id].inject_hardware_error(int(HARDWARE_FAULT_BITS[kind]))
                fault = self.reply_faults.get(self.instructions_received)
                reply = self._handle(item)
                self._rekey()  # an ID written, a Factory Reset: the servo answers at its new ID
                if reply and fault == "drop_reply":
                    reply = b""  # the servo acted; its status was lost on the wire
                elif reply and fault == "garble_reply":
                    reply = reply[:-1] + bytes([reply[-1] ^ 0xFF])
                elif reply and fault == "delay_reply":
                    # not the servo's (it answers within its Return Delay Time) but its link's:
                    # a slow USB-serial adapter or a host too loaded to read in time
                    delay = self.reply_delays.get(self.instructions_received, 1.0)
                    self.late.append((delay, reply))
                    reply = b""
                out += reply
            self._errors_changed()  # a fault raised or a Reboot among these packets
            return bytes(out)

    def supply_lost(self) -> bool:
        """Whether the chain's supply has gone (``power_lost``) by now: its RAM is lost, and
        nothing of its powered state outlives this command (the next meets it at power-on)."""
        with self._lock:
            return self._unpowered(self.instructions_received)

    def _unpowered(self, packet: int) -> bool:
        """Whether the chain's supply is gone (``power_lost``) by the ``packet``-th packet."""
        return self.power_lost_at is not None and packet >= self.power_lost_at

    def take_late(self) -> tuple[float, bytes] | None:
        """The statuses on their way late, as one: ``(longest delay s, bytes)``; None if none."""
        with self._lock:
            if not self.late:
                return None
            delay = max(d for d, _ in self.late)
            data = b"".join(b for _, b in self.late)
            self.late.clear()
            return delay, data

    def add_fault(
        self, at: int, kind: str, servo_id: int | None = None, delay_s: float = 1.0
    ) -> None:
        """Rehearse a fault at the ``at``-th instruction packet: a status lost or damaged
        (``drop_reply``, ``garble_reply``) or servo ``servo_id``'s hardware error (a key of
        :data:`HARDWARE_FAULT_BITS`). One place for a config's ``[[emulator.faults]]`` and the
        manual tool's ``--fault``; several servos' errors at one packet are all raised (they
        had been kept by packet, the last one alone)."""
        if kind in HARDWARE_FAULT_BITS:
            self.hardware_faults.setdefault(at, []).append((int(servo_id or 0), kind))
        elif kind == "power_lost":
            self.power_lost_at = at
        else:
            self.reply_faults[at] = kind
            if kind == "delay_reply":
                self.reply_delays[at] = delay_s

    def _reply(
        self,
        dxl_id: int,
        number: int = 0,
        params: bytes = b"",
        servo: EmulatedServo | None = None,
    ) -> bytes:
        """Servo ``servo``'s (the one at ``dxl_id`` unless given) status, sent as ``dxl_id``."""
        servo = servo if servo is not None else self.servos[dxl_id]
        packet = wire.status_packet(dxl_id, servo.status_error(number), params)
        if self.drop_next_replies > 0:
            self.drop_next_replies -= 1
            return b""
        if self.corrupt_next_replies > 0:
            self.corrupt_next_replies -= 1
            packet = packet[:-1] + bytes([packet[-1] ^ 0xFF])
        return packet

    def _answers(self, servo: EmulatedServo, instruction: int) -> bool:
        level = servo.get(tbl.STATUS_RETURN_LEVEL)
        if instruction == wire.PING:
            return True
        if instruction in (wire.READ, wire.SYNC_READ, wire.BULK_READ):
            return level >= 1
        return level >= 2

    def _rekey(self) -> None:
        """:attr:`servos` by each servo's ID as its table holds it now (in place).

        Why: the map had been built once, and again only after a Factory Reset, by a dict
        comprehension: a servo whose ID (7) was written kept answering at its old ID, and a
        Factory Reset 0xFF (ID back to 1) on a bus where another servo has ID 1 dropped one
        of the two from the bus."""
        by_id: dict[int, EmulatedServo] = {}
        for servo in self.chain:
            by_id.setdefault(servo.dxl_id, servo)
        self.servos.clear()
        self.servos.update(by_id)

    def _on(self, dxl_id: int) -> list[EmulatedServo]:
        """The servos that hear a packet to ``dxl_id`` (several if they share it)."""
        return [s for s in self.chain if s.dxl_id == dxl_id and s not in self._deaf]

    @staticmethod
    def _at_once(statuses: list[bytes]) -> bytes:
        """What the host reads of the statuses sent at once by servos sharing one ID.

        ROBOTIS e-manual, Protocol 2.0, ID: "Each connected DYNAMIXEL must have a unique ID
        number. If DYNAMIXELs with the same ID are connected, packet collision and network
        problems will occur." Both drive the half-duplex line together, each after its own
        Return Delay Time, and the bytes the host reads are neither's: modelled as the first
        status with its CRC damaged (the SDK's COMM_RX_CORRUPT, a retry meets it again), not
        as the bit-level sum of the two, which the manual does not give."""
        sent = [s for s in statuses if s]
        if len(sent) < 2:
            return b"".join(sent)
        return sent[0][:-1] + bytes([sent[0][-1] ^ 0xFF])

    def _targets(self, pkt: wire.Instruction) -> list[EmulatedServo]:
        if pkt.dxl_id == wire.BROADCAST_ID:
            return sorted((s for s in self.chain if s not in self._deaf), key=lambda s: s.dxl_id)
        return self._on(pkt.dxl_id)

    def _log_goal(self, dxl_id: int, address: int, data: bytes) -> None:
        g = tbl.GOAL_POSITION.address
        if address <= g and address + len(data) >= g + 4:
            raw = int.from_bytes(data[g - address : g - address + 4], "little")
            self.goal_log.append((dxl_id, wire.signed(raw, 4)))

    def _handle(self, pkt: wire.Instruction) -> bytes:
        inst, prm = pkt.instruction, pkt.params
        unicast = pkt.dxl_id != wire.BROADCAST_ID
        out = bytearray()
        if inst == wire.SYNC_WRITE:
            address, length = int.from_bytes(prm[0:2], "little"), int.from_bytes(prm[2:4], "little")
            for i in range(4, len(prm), length + 1):
                dxl_id, data = prm[i], prm[i + 1 : i + 1 + length]
                self._log_goal(dxl_id, address, data)
                for servo in self._on(dxl_id):
                    servo.write(address, data)
            return b""
        if inst == wire.BULK_WRITE:
            i = 0
            while i + 5 <= len(prm):
                dxl_id = prm[i]
                address = int.from_bytes(prm[i + 1 : i + 3], "little")
                length = int.from_bytes(prm[i + 3 : i + 5], "little")
                data = prm[i + 5 : i + 5 + length]
                self._log_goal(dxl_id, address, data)
                for servo in self._on(dxl_id):
                    servo.write(address, data)
                i += 5 + length
            return b""
        if inst == wire.SYNC_READ:
            address, length = int.from_bytes(prm[0:2], "little"), int.from_bytes(prm[2:4], "little")
            for dxl_id in prm[4:]:
                out += self._at_once(
                    [
                        self._reply(dxl_id, *s.read(address, length), servo=s)
                        for s in self._on(dxl_id)
                    ]
                )
            return bytes(out)
        if inst == wire.BULK_READ:
            for i in range(0, len(prm) - 4, 5):
                dxl_id = prm[i]
                address = int.from_bytes(prm[i + 1 : i + 3], "little")
                length = int.from_bytes(prm[i + 3 : i + 5], "little")
                out += self._at_once(
                    [
                        self._reply(dxl_id, *s.read(address, length), servo=s)
                        for s in self._on(dxl_id)
                    ]
                )
            return bytes(out)
        statuses: dict[int, list[bytes]] = {}  # by the ID each goes out as
        for servo in self._targets(pkt):
            # a status goes out as the ID the packet reached: a Factory Reset's before the
            # restart, an ID write's before the new ID takes over (the host's SDK takes a
            # status only from the ID it asked)
            answering = servo.dxl_id
            err, params = self._execute(servo, inst, prm, broadcast=not unicast)
            if inst == wire.PING or (unicast and self._answers(servo, inst)):
                statuses.setdefault(answering, []).append(
                    self._reply(answering, err, params, servo=servo)
                )
        for same_id in statuses.values():
            out += self._at_once(same_id)
        return bytes(out)

    def _execute(
        self, servo: EmulatedServo, inst: int, prm: bytes, broadcast: bool = False
    ) -> tuple[int, bytes]:
        if inst == wire.PING:
            model = servo.get(tbl.MODEL_NUMBER)
            return 0, model.to_bytes(2, "little") + bytes([servo.get(tbl.FIRMWARE_VERSION)])
        if inst == wire.READ and len(prm) == 4:
            address, length = int.from_bytes(prm[0:2], "little"), int.from_bytes(prm[2:4], "little")
            return servo.read(address, length)
        if inst in (wire.WRITE, wire.REG_WRITE) and len(prm) >= 3:
            address = int.from_bytes(prm[0:2], "little")
            if inst == wire.WRITE:
                self._log_goal(servo.dxl_id, address, prm[2:])
                return servo.write(address, prm[2:]), b""
            return servo.reg_write(address, prm[2:]), b""
        if inst == wire.ACTION:
            if servo._registered is not None:
                self._log_goal(servo.dxl_id, *servo._registered)
            return servo.action(), b""
        if inst == wire.REBOOT:
            servo.reboot()
            return 0, b""
        if inst == wire.CLEAR and prm == bytes([0x01, 0x44, 0x58, 0x4C, 0x22]):
            return servo.clear_multi_turn(), b""
        if inst == wire.FACTORY_RESET and len(prm) == 1 and prm[0] in FACTORY_RESET_OPTIONS:
            if not (broadcast and prm[0] == 0xFF):  # "will NOT be activated" (Protocol 2.0)
                servo.factory_reset(prm[0])
            return 0, b""
        return wire.INSTRUCTION_ERROR, b""


#: The SDK's reply window beyond the status's bytes, ms (``LATENCY_TIMER * 2 + 2``, its
#: ``PortHandler.setPacketTimeout``, which adds the bytes' wire time at the baud rate).
SDK_REPLY_WINDOW_MS = 34.0


class InProcessPort:
    """A stand-in for ``dynamixel_sdk.PortHandler`` wired straight to an emulator.

    Replies are produced synchronously on write, so "no more bytes" means "timed out": silence
    costs no wall time, but the clock is charged the reply window a real host waits for it, a
    late status its lateness. (The pty transport gives the same guarantee with a causal timeout: see
    :mod:`rti_rig.simulator.dynamixel_pty`.)

    ``clock`` (the emulator's unless given) is charged what a real half-duplex bus takes
    (:class:`~rti_rig.simulator.dynamixel_bus_time.BusTime`): each instruction's wire time at the
    port's baud rate as it is written, each status's Return Delay Time and wire time as it is
    read. Why: replies had come in no time, and a dry run's session time was about 2.5 %
    short of the same schedule on a real bus at 57600 baud."""

    def __init__(
        self, emulator: DynamixelBusEmulator, name: str = "inprocess", clock: Clock | None = None
    ) -> None:
        self.emulator = emulator
        self.port_name = name
        self.is_open = False
        self.is_using = False
        self.baudrate = 1_000_000
        self._rx = bytearray()
        self.tx_log: list[bytes] = []
        self.packet_timeout = SDK_REPLY_WINDOW_MS
        self.bus_time = BusTime(
            clock if clock is not None else emulator.clock, emulator.servos, self.getBaudRate
        )

    def openPort(self) -> bool:
        """Opened at the current baud rate, as the SDK's ``openPort`` (1 Mbps unless set)."""
        self.is_open = True
        self.emulator.host_baud = self.baudrate
        return True

    def closePort(self) -> None:
        self.is_open = False

    def clearPort(self) -> None:
        self._rx.clear()
        self.bus_time.cleared()
        self.emulator.take_late()  # a late status arriving before the clear: discarded too

    def setBaudRate(self, baudrate: int) -> bool:
        self.baudrate = baudrate
        self.emulator.host_baud = baudrate
        return True

    def getBaudRate(self) -> int:
        return self.baudrate

    def getPortName(self) -> str:
        return self.port_name

    def getBytesAvailable(self) -> int:
        return len(self._rx)

    def readPort(self, length: int) -> bytes:
        out = bytes(self._rx[:length])
        del self._rx[:length]
        self.bus_time.heard(out)
        return out

    def writePort(self, packet: Any) -> int:
        if not self.is_open:
            raise OSError(f"{self.port_name}: port is not open")
        data = bytes(packet)
        self.tx_log.append(data)
        self.bus_time.sent(data)  # the servos act once its last byte is in
        self._rx += self.emulator.receive(data)
        return len(data)

    def setPacketTimeout(self, packet_length: int) -> None:
        """The SDK's window (ms), as it computes it: ``packet_length`` bytes at the baud rate
        plus :data:`SDK_REPLY_WINDOW_MS`; the clock's wait for a status counts from here."""
        self.packet_timeout = packet_length * 10_000.0 / self.baudrate + SDK_REPLY_WINDOW_MS
        self.bus_time.window_opened()

    def setPacketTimeoutMillis(self, msec: float) -> None:
        self.packet_timeout = msec
        self.bus_time.window_opened()

    def isPacketTimeout(self) -> bool:
        """Whether the host's window ran out: no status came (the clock is charged the whole
        window, as a real host waits it out), or a late one comes after it (likewise); one
        late but within the window is read after its lateness, charged to the clock."""
        if self._rx:
            return False
        late = self.emulator.take_late()
        if late is None:
            self.bus_time.waited(self.packet_timeout, gave_up=True)
            return True
        self._rx += late[1]  # it comes: within the host's window, or after it
        over = late[0] * 1000.0 > self.packet_timeout
        self.bus_time.waited(self.packet_timeout if over else late[0] * 1000.0, gave_up=over)
        return over


#: How fast the emulated arm's elevation joint falls once its torque goes off (degrees of
#: joint per second). Assumed, not measured: a lamp of a few hundred grams on a 0.45 m arm
#: loads an XL430 near its stall torque (about 1.4 N·m at 12 V), so a back-driven joint falls
#: in seconds, held back by its gear train's friction; the session's check after a capture
#: is what meets it, and any rate of degrees per second is well past every tolerance.
SAG_DEG_PER_S = 10.0


def emulator_for_arm(settings: Any, clock: Clock, at_park: bool = True) -> DynamixelBusEmulator:
    """Servos matching an ``ArmSettings`` (ids, models, modes), resting at the park pose.

    Each is its model's factory table (e-manual Initial Values); their Min/Max Position Limit
    are left at the factory 0..4095, so the driver's connect-time check has something to
    synchronise, as on a fresh servo; each sees its model's recommended supply voltage."""
    from rti_rig.drivers.dynamixel.kinematics import (
        ArmKinematics,  # the emulator speaks their geometry
    )

    kin = ArmKinematics(settings)
    park = kin.ticks_of_pose(settings.park_azimuth_deg, settings.park_elevation_deg)
    servos = []
    for joint, ticks in zip(settings.joints, park, strict=True):
        servos.append(
            EmulatedServo(
                joint.servo_id,
                joint.model_number,
                clock,
                operating_mode=int(joint.mode),
                present_ticks=ticks if at_park else 2048,
            )
        )
    # the elevation joint carries the lamp: with its torque off it falls to its lower limit
    # (the lamp on its stop) at SAG_DEG_PER_S, an assumption (see EmulatedServo._go_limp)
    elevation = servos[1]
    elevation.sag_to = float(
        kin.ticks_of_pose(settings.park_azimuth_deg, settings.elevation.min_deg)[1]
    )
    elevation.sag_ticks_per_s = (
        SAG_DEG_PER_S * tbl.TICKS_PER_REV / 360.0 * settings.elevation.gear_ratio
    )
    dual = [s for s in servos if s.get(tbl.MODEL_NUMBER) in tbl.DUAL_AXIS_MODELS]
    if len(dual) == 2:  # both joints on one two-axis servo (a 2XL430 pan-tilt)
        dual[0].other_axes, dual[1].other_axes = [dual[1]], [dual[0]]
    return DynamixelBusEmulator(servos, clock)


def lamp_direction(emulator: DynamixelBusEmulator, settings: Any) -> Any:
    """Unit direction of the lamp *now* (emulator time), from the servos' present positions:
    what a simulated camera should render, wherever the arm really is (even mid-move)."""
    from rti_rig.drivers.dynamixel.kinematics import ArmKinematics

    pos = emulator.joint_positions()
    return ArmKinematics(settings).direction_of_ticks(
        pos[settings.azimuth.servo_id], pos[settings.elevation.servo_id]
    )


@contextlib.contextmanager
def emulated_arm_port(
    settings: Any, clock: Clock, transport: str = "pty"
) -> Iterator[tuple[Any, DynamixelBusEmulator]]:
    """``(port, emulator)`` for a dry run of ``DynamixelArm`` against emulated servos.

    ``transport="pty"``: the SDK's ``PortHandler`` on a pseudo-terminal served by a thread (the
    real SDK packet code and pyserial run unchanged; reply timeouts are causal, so a loaded
    machine cannot make a present servo time out: see :mod:`rti_rig.simulator.dynamixel_pty`);
    ``"inprocess"``: an :class:`InProcessPort`
    (no thread, no pty; fastest). The server is stopped on exit."""
    emulator = emulator_for_arm(settings, clock)
    if transport == "inprocess":
        yield InProcessPort(emulator, clock=clock), emulator
        return
    if transport != "pty":
        raise ValueError(f"transport must be 'pty' or 'inprocess', not {transport!r}")
    from rti_rig.simulator.dynamixel_pty import PtyServoServer

    server = PtyServoServer(emulator)
    server.start()
    try:
        yield server.port_handler(clock), emulator
    finally:
        server.stop()


#: The rig config whose arm the manual tool emulates when none is given (shipped, installed).
MANUAL_DEFAULT_CONFIG = "simulated_arm.toml"


def arm_settings_of(config: str | None) -> tuple[Any, str]:
    """``(ArmSettings, where)`` of a rig config's ``[arm.dynamixel]`` table (default: the
    shipped ``simulated_arm.toml``); a ``ValueError`` names the file and what is wrong."""
    import tomllib
    from importlib import resources
    from pathlib import Path

    from pydantic import ValidationError

    from rti_rig.drivers.dynamixel.settings import ArmSettings

    if config is None:
        path = Path(str(resources.files("rti_rig.rig_configs").joinpath(MANUAL_DEFAULT_CONFIG)))
    else:
        path = Path(config)
    try:
        table = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ValueError(f"{shown_path(path)}: cannot read it as a rig config: {exc}") from None
    arm = table.get("arm", {}).get("dynamixel")
    if not isinstance(arm, dict):
        raise ValueError(
            f"{shown_path(path)}: no [arm.dynamixel] table: give a servo-arm rig config"
        )
    try:
        return ArmSettings.model_validate(arm), str(path)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(p) for p in first["loc"])
        raise ValueError(
            f"{shown_path(path)}: key 'arm.dynamixel.{where}': {first['msg']}"
        ) from None


@contextlib.contextmanager
def served_arm(
    settings: Any,
    clock: Clock,
    baudrate: int = 57600,
    faults: Iterable[ToolFault] = (),
) -> Iterator[tuple[Any, DynamixelBusEmulator]]:
    """``(server, emulator)``: the servos of ``settings`` (ids, models, modes) resting at its
    park pose, served on a pty for any client (the manual tool; a plain SDK ``PortHandler``).

    ``baudrate``: the rate the servos are set to (their Baud Rate (8), factory 57600 on the
    X series); they answer only a host at that rate, as real servos do (ROBOTIS e-manual,
    Baud Rate: the host and the servo must use the same rate). The tool had always served
    57600, so a bus a user had set to 1 Mbps could not be rehearsed.

    ``faults``: :class:`ToolFault`, as a rig config's ``[[emulator.faults]]``
    (:func:`parse_tool_fault`): the status of the K-th instruction packet lost, damaged or
    late, or a servo's own hardware error raised as it arrives.

    The tool had served two XL430s at 2048 ticks each: on the shipped arm's geometry
    (elevation zero at 1024 ticks) that is 90° elevation, inside every keep-out cone, so a
    ``check`` pointed at it was refused at once ("the arm is not in a safe pose … move it by
    hand"). The park pose is, by validation, reachable and outside the cone."""
    from rti_rig.simulator.dynamixel_pty import PtyServoServer

    codes = {rate: code for code, rate in tbl.BAUD_CODES.items()}
    if baudrate not in codes:
        raise ValueError(
            f"baud rate {baudrate}: an X-series servo's Baud Rate (8) is one of "
            + ", ".join(str(r) for r in codes)
        )
    emulator = emulator_for_arm(settings, clock)
    for servo in emulator.servos.values():
        servo._set(tbl.BAUD_RATE, codes[baudrate])
    for fault in faults:
        emulator.add_fault(fault.at, fault.kind, fault.servo_id, fault.delay_s)
    with PtyServoServer(emulator) as server:
        yield server, emulator


#: What the manual tool's ``--fault`` takes, as a rig config's ``[[emulator.faults]]`` on an
#: arm: a status packet lost, damaged or late, or a servo's own hardware error.
TOOL_FAULT_KINDS = (
    "drop_reply",
    "garble_reply",
    "delay_reply",
    "power_lost",
    *HARDWARE_FAULT_BITS,
)

#: A ``delay_reply``'s lateness bounds and default (s), as ``[[emulator.faults]]`` ``delay_s``.
TOOL_DELAY_S = (0.0, 60.0, 1.0)


class ToolFault(NamedTuple):
    """One ``--fault`` of the manual tool: at the ``at``-th instruction packet, ``kind`` (on
    servo ``servo_id`` for a hardware error), a ``delay_reply``'s status ``delay_s`` late."""

    at: int
    kind: str
    servo_id: int | None = None
    delay_s: float = TOOL_DELAY_S[2]

    def said(self) -> str:
        """The tool's ``Fault:`` line, so a user sees what the served servos will do."""
        if self.servo_id is not None:
            whose = f"servo {self.servo_id}'s {self.kind}"
        elif self.kind == "delay_reply":
            whose = f"delay_reply (its status {self.delay_s:g} s late)"
        elif self.kind == "power_lost":
            silent = "power_lost (no servo hears or answers)"
            return f"Fault: {silent} from instruction packet {self.at}"
        else:
            whose = f"{self.kind} (its status)"
        return f"Fault: {whose} at instruction packet {self.at}"


def parse_tool_fault(spec: str, servo_ids: Iterable[int]) -> ToolFault:
    """``K:KIND`` (a status lost or damaged), ``K:delay_reply[:SECONDS]`` (a status late, 1 s
    unless given) or ``K:KIND:ID`` (servo ID's hardware error) as a :class:`ToolFault`; a
    ValueError that says what to give otherwise.

    Why: the dome firmware tool took ``--fault`` and this one did not, so a servo's overload
    could be rehearsed through a rig config's ``[[emulator.faults]]`` but not on the served
    pty a user points a hardware config at; a late status (``delay_reply`` with ``delay_s``,
    a slow adapter's) could be rehearsed in a config but not here either."""
    ids = sorted(servo_ids)
    parts = spec.split(":")
    low, high, default = TOOL_DELAY_S
    usage = (
        f"--fault {spec}: give K:KIND, K:delay_reply:SECONDS for a status that late "
        f"({low:g} to {high:g}, default {default:g}) or, for a servo's hardware error, "
        f"K:KIND:ID (K the instruction packet, 1 = the first; KIND one of "
        f"{', '.join(TOOL_FAULT_KINDS)}; ID one of {', '.join(map(str, ids))})"
    )
    if len(parts) not in (2, 3) or parts[1] not in TOOL_FAULT_KINDS:
        raise ValueError(usage)
    kind = parts[1]
    delay_s = default
    try:
        at = int(parts[0])
        if kind == "delay_reply" and len(parts) == 3:
            delay_s = float(parts[2])
            parts.pop()
        dxl_id = int(parts[2]) if len(parts) == 3 else None
    except ValueError:
        raise ValueError(usage) from None
    if at < 1 or not low <= delay_s <= high:
        raise ValueError(usage)
    if kind in HARDWARE_FAULT_BITS and dxl_id not in ids:
        raise ValueError(f"{usage}: {kind} is a servo's own error, so it needs the servo's id")
    if kind not in HARDWARE_FAULT_BITS and dxl_id is not None:
        raise ValueError(f"{usage}: {kind} is the bus's, not a servo's: give no id")
    return ToolFault(at, kind, dxl_id, delay_s)


def main(argv: list[str] | None = None) -> int:  # pragma: no cover - manual tool
    """Serve a rig config's arm servos (default: rig_configs/simulated_arm.toml) on a pty,
    resting at its park pose, in real time until Ctrl-C.

    Run as ``python -m rti_rig.simulator.dynamixel_emulator [--config RIG.toml]``, then point a
    copy of that config at the printed port (``backend = "hardware"``, ``[arm.dynamixel] port``,
    a ``[camera.device]``) and run ``rti-rig check`` on it (docs/protocols/dynamixel-arm.md)."""
    import argparse

    from rti_rig.core.clock import SystemClock
    from rti_rig.simulator.pty_link import sigterm_as_ctrl_c

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument(
        "--config",
        default=None,
        help=f"a servo-arm rig config whose [arm.dynamixel] servos to emulate (default: the "
        f"shipped {MANUAL_DEFAULT_CONFIG})",
    )
    parser.add_argument("--seconds", type=float, default=None, help="stop after this long")
    parser.add_argument(
        "--baud",
        type=int,
        default=57600,
        help="the baud rate the servos are set to (default 57600, the X series' factory rate); "
        "they answer only at it",
    )
    parser.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="K:KIND[:ID|:SECONDS]",
        help="as [[emulator.faults]]: at the K-th instruction packet, the status lost or "
        "damaged (drop_reply, garble_reply), late by SECONDS (K:delay_reply:SECONDS, as "
        "delay_s; 1 s unless given), every servo silent from then on (power_lost: the chain's "
        "supply gone), or servo ID's hardware error (overload, "
        "overheating, input_voltage, electrical_shock: the Alert bit until a Reboot, torque "
        "off where its Shutdown selects it); repeatable",
    )
    args = parser.parse_args(argv)
    if args.baud not in tbl.BAUD_CODES.values():
        parser.error(
            f"--baud {args.baud}: an X-series servo runs at one of "
            + ", ".join(str(r) for r in tbl.BAUD_CODES.values())
        )
    try:
        settings, where = arm_settings_of(args.config)
    except ValueError as exc:
        parser.error(str(exc))
    ids = (settings.azimuth.servo_id, settings.elevation.servo_id)
    try:
        faults = [parse_tool_fault(spec, ids) for spec in args.fault]
    except ValueError as exc:
        parser.error(str(exc))
    factory = " (a new servo's factory rate)" if args.baud == 57600 else ""
    # remove the pty on SIGTERM too (the handler before is put back when serving ends)
    with sigterm_as_ctrl_c(), served_arm(settings, SystemClock(), args.baud, faults) as served:
        server = served[0]
        ids = ", ".join(
            f"{j.servo_id} ({name}, model {j.model_number})"
            for name, j in (("azimuth", settings.azimuth), ("elevation", settings.elevation))
        )
        print(
            f"emulated servos {ids} at {args.baud} baud{factory}, resting at the "
            f"park pose of {where} (azimuth {settings.park_azimuth_deg:g}°, elevation "
            f"{settings.park_elevation_deg:g}°), on {server.device_path}",
            flush=True,
        )
        print(
            f'In a copy of that config set backend = "hardware", [arm.dynamixel] port = '
            f'"{server.device_path}" and a [camera.device], then: rti-rig check COPY.toml. '
            "Ctrl-C stops the servos.",
            flush=True,
        )
        for fault in faults:
            print(fault.said(), flush=True)
        if settings.baudrate != args.baud:
            print(
                f"Note: the config's [arm.dynamixel] baudrate = {settings.baudrate}, but these "
                f"servos talk at {args.baud}: none answers at {settings.baudrate}, as on a "
                "real bus",
                flush=True,
            )
        try:
            end = None if args.seconds is None else time.monotonic() + args.seconds
            while end is None or time.monotonic() < end:
                time.sleep(0.2)
        except KeyboardInterrupt:
            pass
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
