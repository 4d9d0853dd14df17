"""Each emulated model leaves the factory with the ROBOTIS e-manual's Initial Values.

The expected values are transcribed here from the e-manual pages (repo ROBOTIS-GIT/emanual,
docs/en/dxl/x/<model>.md; commits in rti_rig.simulator.dynamixel_models), not imported from
the data module, so that a slip in either shows up."""

from __future__ import annotations

import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.bus import DxlBus
from rti_rig.drivers.dynamixel.faults import HardwareFaultError, ServoStatusError
from rti_rig.simulator.dynamixel_emulator import (
    DynamixelBusEmulator,
    EmulatedServo,
    InProcessPort,
)
from rti_rig.simulator.dynamixel_models import FACTORY_TABLES

# model: Return Delay, Temperature Limit, Max/Min Voltage, PWM Limit, Current Limit (None: the
# model has none), Velocity Limit, Max/Min Position, Shutdown, Moving Threshold, Status Return
EMANUAL = {
    1060: (250, 72, 140, 60, 885, None, 265, 4095, 0, 52, 10, 2),  # XL430-W250
    1090: (250, 72, 140, 60, 885, None, 250, 4095, 0, 52, 10, 2),  # 2XL430-W250
    1020: (250, 80, 160, 95, 885, 1193, 200, 4095, 0, 52, 10, 2),  # XM430-W350
    1030: (250, 80, 160, 95, 885, 1193, 330, 4095, 0, 52, 10, 2),  # XM430-W210
    1000: (250, 80, 160, 95, 885, 648, 130, 4095, 0, 52, 10, 2),  # XH430-W350
    1120: (250, 80, 160, 95, 885, 2047, 128, 4095, 0, 52, 10, 2),  # XM540-W270
    1200: (250, 70, 70, 35, 885, 1750, 445, 4095, 0, 53, 10, 2),  # XL330-M288
}
REGISTERS = (
    ct.RETURN_DELAY_TIME,
    ct.TEMPERATURE_LIMIT,
    ct.MAX_VOLTAGE_LIMIT,
    ct.MIN_VOLTAGE_LIMIT,
    ct.PWM_LIMIT,
    ct.CURRENT_LIMIT,
    ct.VELOCITY_LIMIT,
    ct.MAX_POSITION_LIMIT,
    ct.MIN_POSITION_LIMIT,
    ct.SHUTDOWN,
    ct.MOVING_THRESHOLD,
    ct.STATUS_RETURN_LEVEL,
)


def one_servo(model: int, **kwargs) -> tuple[DxlBus, DynamixelBusEmulator]:  # type: ignore[no-untyped-def]
    clock = VirtualClock()
    emu = DynamixelBusEmulator([EmulatedServo(1, model, clock, **kwargs)], clock)
    bus = DxlBus(InProcessPort(emu), "arm")
    bus.open(57600)
    return bus, emu


def test_every_model_the_driver_accepts_has_a_cited_factory_table() -> None:
    assert set(FACTORY_TABLES) == set(ct.MODEL_NAMES) == set(EMANUAL)
    for number, table in FACTORY_TABLES.items():
        assert table.name == ct.MODEL_NAMES[number]
        assert table.source_path == f"docs/en/dxl/x/{table.name.lower()}.md"
        assert len(table.source_commit) == 40


@pytest.mark.parametrize("model", sorted(EMANUAL))
def test_each_model_reports_its_emanual_factory_values_over_the_bus(model: int) -> None:
    bus, _emu = one_servo(model)
    assert bus.ping(1) == model
    for reg, expected in zip(REGISTERS, EMANUAL[model], strict=True):
        if expected is None:
            continue  # no such register on this model (address 38 is reserved there)
        assert bus.read(1, reg) == expected, f"{ct.MODEL_NAMES[model]} {reg.name}"
    assert bus.read(1, ct.BAUD_RATE) == 1 and bus.read(1, ct.OPERATING_MODE) == 3
    assert bus.read(1, ct.HARDWARE_ERROR_STATUS) == 0  # its recommended supply is in range


@pytest.mark.parametrize(
    ("model", "torque_after"), [(1200, False), (1060, True)], ids=["XL330", "XL430"]
)
def test_an_injected_input_voltage_error_shuts_down_an_xl330_only(
    model: int, torque_after: bool
) -> None:
    """XL330-M288 Shutdown 53 = 0x35 selects the Input Voltage Error bit; XL430-W250's 52 =
    0x34 does not. The driver's error says the torque as read, either way."""
    bus, emu = one_servo(model)
    bus.write(1, ct.TORQUE_ENABLE, 1)
    emu.inject_hardware_error(1, ct.HardwareFault.INPUT_VOLTAGE)
    assert emu.servos[1].torque_on is torque_after
    assert emu.servos[1].shut_down is (not torque_after)
    with pytest.raises(HardwareFaultError) as info:
        bus.read(1, ct.PRESENT_POSITION)
    assert info.value.fault_names == ["input_voltage"]
    assert info.value.torque_on is torque_after
    text = str(info.value)
    if torque_after:
        assert "still ON" in text and "limp" not in text
    else:
        assert "limp" in text and "still ON" not in text


def test_a_supply_outside_the_voltage_limits_raises_the_input_voltage_error() -> None:
    """An XL330 (limits 3.5..7.0 V) on the 12 V an XL430 arm is fed: error and shutdown."""
    bus, emu = one_servo(1200)
    assert bus.read(1, ct.PRESENT_INPUT_VOLTAGE) == 50  # recommended 5.0 V
    bus.write(1, ct.TORQUE_ENABLE, 1)
    emu.set_input_voltage(1, 120)
    assert emu.servos[1].hardware_error == ct.HardwareFault.INPUT_VOLTAGE
    assert not emu.servos[1].torque_on
    with pytest.raises(HardwareFaultError) as info:
        bus.read(1, ct.PRESENT_POSITION)
    assert info.value.voltage == (120, 35, 70)
    assert "input 12.0 V as read; this servo's limits are 3.5..7.0 V" in str(info.value)
    # an XL430 at 12.0 V is inside its 6.0..14.0 V
    bus, emu = one_servo(1060, supply_decivolts=120)
    assert bus.read(1, ct.HARDWARE_ERROR_STATUS) == 0


def test_profile_velocity_above_the_velocity_limit_is_a_data_limit_error() -> None:
    bus, _emu = one_servo(1000)  # XH430-W350: Velocity Limit 130
    bus.write(1, ct.PROFILE_VELOCITY, 130)
    with pytest.raises(ServoStatusError, match="data limit"):
        bus.write(1, ct.PROFILE_VELOCITY, 131)
    assert bus.read(1, ct.PROFILE_VELOCITY) == 130
    # time-based profile: Profile Velocity is a time span (ms), not bounded by the limit
    bus.write(1, ct.DRIVE_MODE, ct.DRIVE_MODE_TIME_BASED_PROFILE)
    bus.write(1, ct.PROFILE_VELOCITY, 2000)
