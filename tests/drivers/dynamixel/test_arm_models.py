"""The arm driver against each model's e-manual factory table (not one table for all)."""

from __future__ import annotations

import pytest
from dxl_support import arm_settings

from rti_rig.core.clock import VirtualClock
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.faults import ConfigMismatchError, HardwareFaultError
from rti_rig.simulator.dynamixel_emulator import InProcessPort, emulator_for_arm


def make_arm(model: int, rpm: float = 20.0):  # type: ignore[no-untyped-def]
    joint = dict(model_number=model, profile_velocity_rpm=rpm)
    settings = arm_settings(azimuth=joint, elevation=joint)
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    return DynamixelArm(settings, InProcessPort(emu), clock), emu, clock


@pytest.mark.parametrize("model", sorted(ct.MODEL_NAMES))
def test_the_default_arm_connects_and_moves_on_every_model(model: int) -> None:
    arm, emu, _clock = make_arm(model)
    with arm:
        arm.move_to(direction_from_az_el(60, 40))
    assert not any(s.hardware_error for s in emu.servos.values())


@pytest.mark.parametrize(
    ("model", "rpm", "accepted"),
    [
        (1000, 29.0, True),  # XH430-W350: Velocity Limit 130 = 29.8 rpm
        (1000, 40.0, False),
        (1120, 40.0, False),  # XM540-W270: 128 = 29.3 rpm
        (1060, 100.0, False),  # XL430-W250: 265 = 60.7 rpm
        (1200, 100.0, True),  # XL330-M288: 445 = 101.9 rpm
    ],
)
def test_a_profile_velocity_above_the_models_velocity_limit_fails_connect_before_any_write(
    model: int, rpm: float, accepted: bool
) -> None:
    """The servo refuses a Profile Velocity above its Velocity Limit (Data Limit Error), and
    the factory limit differs per model: the connect had failed half-way, after rewriting
    the position limits (EEPROM, torque off), with a bare "data limit error"."""
    arm, emu, _clock = make_arm(model, rpm)
    if accepted:
        arm.connect()
        arm.close()
        return
    with pytest.raises(ConfigMismatchError, match="profile_velocity_rpm") as info:
        arm.connect()
    limit = emu.servos[1].factory.velocity_limit
    assert f"Velocity Limit {limit} ({limit * 0.229:.1f} rpm" in str(info.value)
    assert not arm.commanded  # nothing written: the servo is as it was
    for servo in emu.servos.values():
        assert not servo.torque_on
        assert servo.get(ct.MIN_POSITION_LIMIT) == 0 and servo.get(ct.MAX_POSITION_LIMIT) == 4095


@pytest.mark.parametrize(
    ("model", "torque_after"), [(1200, False), (1060, True)], ids=["XL330", "XL430"]
)
def test_an_input_voltage_error_mid_move_is_reported_as_the_torque_reads(
    model: int, torque_after: bool
) -> None:
    """XL330 (Shutdown 0x35) drops torque on an input-voltage error; XL430 (0x34) drives on.
    The arm's error says which, from Torque Enable as read, and names the supply and limits."""
    arm, emu, clock = make_arm(model)
    arm.connect()
    real_sleep = clock.sleep

    def sleep_then_sag(s: float) -> None:
        real_sleep(s)
        if clock.now() > 0.3 and not emu.servos[1].hardware_error:
            emu.inject_hardware_error(1, ct.HardwareFault.INPUT_VOLTAGE)

    clock.sleep = sleep_then_sag  # type: ignore[method-assign]
    with pytest.raises(HardwareFaultError) as info:
        arm.move_to(direction_from_az_el(150, 30))
    clock.sleep = real_sleep  # type: ignore[method-assign]
    assert info.value.fault_names == ["input_voltage"]
    assert info.value.torque_on is torque_after
    assert emu.servos[1].torque_on is torque_after
    text = str(info.value)
    assert ("still ON" in text) is torque_after and ("limp" in text) is (not torque_after)
    # recommended supply and voltage limits (e-manual): XL330 5.0 V in 3.5..7.0, XL430 11.1 V
    # in 6.0..14.0
    supply, low, high = (5.0, 3.5, 7.0) if model == 1200 else (11.1, 6.0, 14.0)
    # the supply reads within the limits (the sag passed): said so, the error kept until a reboot
    assert f"input {supply:.1f} V as read, within this servo's limits {low}..{high} V now" in text
    if torque_after:
        arm.close()  # held: the stop completes
    else:
        # servo 1 is the azimuth: limp, the arm turns about the vertical (it had said "sag")
        with pytest.raises(Exception, match=r"\(the arm turns freely\)"):
            arm.close()


def test_an_xl330_on_a_12_volt_supply_is_refused_at_connect_naming_the_voltage() -> None:
    """An XL330 arm wired to the 12 V supply an XL430 arm uses: its Input Voltage Error is set
    (limits 3.5..7.0 V), and the connect says the supply and the limits, not only "check the
    power supply voltage against the servo's limits"."""
    arm, emu, _clock = make_arm(1200)
    for sid in (1, 2):
        emu.set_input_voltage(sid, 120)
    with pytest.raises(HardwareFaultError) as info:
        arm.connect()
    assert "input 12.0 V as read; this servo's limits are 3.5..7.0 V" in str(info.value)
    assert info.value.torque_on is False


def test_a_second_joints_profile_velocity_above_its_limit_fails_connect_before_any_write() -> None:
    """Every joint is checked before anything is written to any servo: an XL430 azimuth (its
    position limits to synchronise) and an XM540 elevation at 40 rpm (Velocity Limit 128 =
    29.3 rpm). The check ran per joint, after the previous joint's EEPROM position limits had
    been rewritten (torque off, two EEPROM writes) — a connect that failed half-way."""
    settings = arm_settings(
        azimuth=dict(model_number=1060, profile_velocity_rpm=40.0),
        elevation=dict(model_number=1120, profile_velocity_rpm=40.0),
    )
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    arm = DynamixelArm(settings, InProcessPort(emu), clock)
    with pytest.raises(ConfigMismatchError, match="profile_velocity_rpm") as info:
        arm.connect()
    # the config table to change is named, not only the servo id
    assert "[arm.dynamixel.elevation] profile_velocity_rpm = 40" in str(info.value)
    assert not arm.commanded
    for servo in emu.servos.values():
        assert servo.get(ct.MIN_POSITION_LIMIT) == 0 and servo.get(ct.MAX_POSITION_LIMIT) == 4095


def test_a_servo_of_another_model_is_named_with_the_config_table_to_fix() -> None:
    settings = arm_settings(elevation=dict(model_number=1020))
    clock = VirtualClock()
    emu = emulator_for_arm(arm_settings(), clock)  # two XL430s on the bus
    arm = DynamixelArm(settings, InProcessPort(emu), clock)
    with pytest.raises(ConfigMismatchError, match="model number 1060") as info:
        arm.connect()
    assert "fix model_number or servo_id in [arm.dynamixel.elevation]" in str(info.value)


def test_new_limits_on_a_2xl430_held_from_an_earlier_session_are_written() -> None:
    """A 2XL430-W250 pan-tilt (two axes, one body) locks its EEPROM while *either* axis has
    torque on (e-manual, control table Area, 2XL430 branch). The arm left holding by the last
    session (torque policy "hold"), and the config's azimuth limits then changed: the connect
    switched off the azimuth axis alone and failed on "access error" writing the new limits."""
    arm, emu, clock = make_arm(1090)
    arm.connect()
    arm.close()
    assert all(s.torque_on for s in emu.servos.values())  # holding, as "hold" says
    wider = dict(model_number=1090, profile_velocity_rpm=20.0, min_deg=-160.0)
    settings = arm_settings(azimuth=wider, elevation=dict(model_number=1090))
    again = DynamixelArm(settings, InProcessPort(emu), clock)
    with again:
        again.move_to(direction_from_az_el(-150, 40))
    assert emu.servos[1].get(ct.MIN_POSITION_LIMIT) == settings.azimuth.tick_limits[0]


def test_the_emulated_2xl430_locks_its_eeprom_while_either_axis_holds() -> None:
    arm, emu, _clock = make_arm(1090)
    arm.connect()
    emu.servos[1].table[ct.TORQUE_ENABLE.address] = 0  # one axis off, the other holding
    assert emu.servos[1].write(ct.MIN_POSITION_LIMIT.address, (100).to_bytes(4, "little")) == 7
    arm, emu, _clock = make_arm(1060)  # two XL430s: two bodies, each its own lock
    arm.connect()
    emu.servos[1].table[ct.TORQUE_ENABLE.address] = 0
    assert emu.servos[1].write(ct.MIN_POSITION_LIMIT.address, (100).to_bytes(4, "little")) == 0
