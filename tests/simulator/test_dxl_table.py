"""The emulator's own Dynamixel control tables (rti_rig.simulator.dynamixel_table): a few values
as the ROBOTIS e-manual publishes them, and a cross-check that the driver's control_table agrees
with them on every register the driver names (a check of both against each other: neither is
derived from the other, so a register-map bug in either shows here)."""

from __future__ import annotations

import pytest

from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.simulator import dynamixel_table as tbl


def _by_address(model: int) -> dict[int, tbl.Item]:
    return {i.address: i for i in tbl.control_table(model)}


def test_published_values_of_the_xl430_and_xm430_pages():
    """Rows of docs/en/dxl/x/xl430-w250.md and xm430-w350.md (ROBOTIS-GIT/emanual)."""
    xl, xm = _by_address(1060), _by_address(1020)
    assert (xl[0].name, xl[0].initial, xm[0].initial) == ("Model Number", 1060, 1020)
    for t in (xl, xm):
        assert (t[132].name, t[132].size, t[132].access, t[132].area) == (
            "Present Position",
            4,
            "R",
            "RAM",
        )
        assert (t[116].name, t[116].size, t[116].access) == ("Goal Position", 4, "RW")
        assert (t[64].name, t[64].size, t[64].area, t[64].initial) == ("Torque Enable", 1, "RAM", 0)
        assert (t[9].name, t[9].size, t[9].area, t[9].initial) == (
            "Return Delay Time",
            1,
            "EEPROM",
            250,
        )
        assert (t[8].name, t[8].initial) == ("Baud Rate", 1)
        assert (t[70].name, t[70].access) == ("Hardware Error Status", "R")
        assert (t[168].name, t[168].initial) == ("Indirect Address 1", 224)
        assert (t[632].name, t[632].initial) == ("Indirect Address 56", 661)
    # the XL430-W250 has no Current Limit, and 126 is Present Load; the XM430 has both currents
    assert 38 not in xl and xl[126].name == "Present Load"
    assert (xm[38].name, xm[38].size, xm[38].area) == ("Current Limit", 2, "EEPROM")
    assert xm[126].name == "Present Current"
    assert tbl.BAUD_CODES == {
        0: 9600, 1: 57600, 2: 115200, 3: 1_000_000,
        4: 2_000_000, 5: 3_000_000, 6: 4_000_000, 7: 4_500_000,
    }  # fmt: skip
    assert tbl.TABLE_SIZE == 662  # Indirect Data 56 is at 661


@pytest.mark.parametrize("model", sorted(tbl.MODEL_NAMES))
def test_every_model_table_is_well_formed(model):
    """No two items overlap, none runs past the table, EEPROM below 64 and RAM from 64."""
    items = tbl.control_table(model)
    end = 0
    for item in items:
        assert item.address >= end, f"{item.name} overlaps the item before it"
        end = item.address + item.size
        assert item.eeprom == (item.address < tbl.EEPROM_END), item.name
        assert item.access in ("R", "RW")
    assert end <= tbl.TABLE_SIZE


#: Where the driver's table and the e-manual differ, said: the driver names Current Limit for
#: every model, the XL430-W250 and 2XL430-W250 pages have none (its docstring says so; the
#: driver writes it only to models that have it).
DRIVER_ONLY = {(1060, ct.CURRENT_LIMIT.address), (1090, ct.CURRENT_LIMIT.address)}


def _driver_registers() -> list[ct.Register]:
    return [r for r in vars(ct).values() if isinstance(r, ct.Register)]


@pytest.mark.parametrize("model", sorted(ct.MODEL_NAMES))
def test_the_driver_and_the_emulator_agree_on_every_register_the_driver_names(model):
    items = _by_address(model)
    wrong = []
    for reg in _driver_registers():
        if (model, reg.address) in DRIVER_ONLY:
            assert reg.address not in items
            continue
        item = items.get(reg.address)
        mine = (reg.size, reg.eeprom, reg.writable, reg.signed)
        theirs = item and (item.size, item.eeprom, item.writable, item.signed)
        if mine != theirs:
            wrong.append(f"{reg.name} at {reg.address}: driver {mine}, e-manual {theirs}")
    assert wrong == []


def test_the_driver_and_the_emulator_agree_on_models_baud_codes_and_error_bits():
    assert ct.MODEL_NAMES == tbl.MODEL_NAMES
    assert ct.DUAL_AXIS_MODELS == tbl.DUAL_AXIS_MODELS
    assert ct.BAUD_CODES == tbl.BAUD_CODES
    assert (ct.TABLE_SIZE, ct.EEPROM_END) == (tbl.TABLE_SIZE, tbl.EEPROM_END)
    assert {f.name: f.value for f in ct.HardwareFault} == {
        "INPUT_VOLTAGE": tbl.INPUT_VOLTAGE_ERROR,
        "OVERHEATING": tbl.OVERHEATING_ERROR,
        "MOTOR_ENCODER": tbl.MOTOR_ENCODER_ERROR,
        "ELECTRICAL_SHOCK": tbl.ELECTRICAL_SHOCK_ERROR,
        "OVERLOAD": tbl.OVERLOAD_ERROR,
    }
    assert (ct.OperatingMode.POSITION, ct.OperatingMode.EXTENDED_POSITION) == (
        tbl.POSITION_MODE,
        tbl.EXTENDED_POSITION_MODE,
    )
    assert ct.EXTENDED_TICK_LIMIT == tbl.EXTENDED_TICK_LIMIT
    assert ct.DRIVE_MODE_TIME_BASED_PROFILE == tbl.DRIVE_MODE_TIME_BASED_PROFILE
    assert (ct.TICKS_PER_REV, ct.RPM_PER_VELOCITY_UNIT, ct.REV_MIN2_PER_ACCEL_UNIT) == (
        tbl.TICKS_PER_REV,
        tbl.RPM_PER_VELOCITY_UNIT,
        tbl.REV_MIN2_PER_ACCEL_UNIT,
    )


def test_every_factory_table_has_a_control_table_and_a_servo_starts_from_its_initial_values():
    """The emulated servo starts from its table's published Initial Values, RAM included
    (Indirect Address 1 = 224, Velocity P Gain 100, Status Return Level 2), read back through
    the real SDK; they had been zero wherever the driver named no register."""
    import dynamixel_sdk as sdk

    from rti_rig.core.clock import VirtualClock
    from rti_rig.simulator.dynamixel_emulator import (
        DynamixelBusEmulator,
        EmulatedServo,
        InProcessPort,
    )
    from rti_rig.simulator.dynamixel_models import FACTORY_TABLES

    assert set(FACTORY_TABLES) == set(tbl.MODEL_NAMES)
    clock = VirtualClock()
    port = InProcessPort(DynamixelBusEmulator([EmulatedServo(1, 1060, clock)], clock))
    assert port.openPort() and port.setBaudRate(57600)
    ph = sdk.PacketHandler(2.0)
    for item, value in (
        (tbl.control_table(1060)[0], 1060),
        (tbl.VELOCITY_P_GAIN, 100),
        (tbl.STATUS_RETURN_LEVEL, 2),
        (_by_address(1060)[168], 224),
        (_by_address(1060)[632], 661),
    ):
        read = {1: ph.read1ByteTxRx, 2: ph.read2ByteTxRx}[item.size]
        assert read(port, 1, item.address) == (value, sdk.COMM_SUCCESS, 0), item.name
