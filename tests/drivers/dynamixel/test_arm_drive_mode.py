"""Dynamixel: Drive Mode bit 3 and lost status packets (issue #30, finding 9).

Drive Mode (address 10) bit 3, "Torque On by Goal Update" (firmware 45 and later, ROBOTIS
e-manual): a Goal Position written while torque is off switches torque on and the servo moves.
After an emergency stop (torque off) the driver's closing goal write would then bring the arm
back to life. A lost or corrupt status packet fails one exchange; a read is safe to retry.
"""

from __future__ import annotations

import pytest
from dxl_support import arm_settings

from rti_rig.core.clock import VirtualClock
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.faults import CommunicationError, ConfigMismatchError
from rti_rig.simulator.dynamixel_emulator import EmulatedServo, InProcessPort, emulator_for_arm


def make_arm(drive_mode: int = 0, firmware: int | None = None):  # type: ignore[no-untyped-def]
    settings = arm_settings()
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    for servo in emu.servos.values():
        servo._set(ct.DRIVE_MODE, drive_mode)
        if firmware is not None:
            servo._set(ct.FIRMWARE_VERSION, firmware)
    return DynamixelArm(settings, InProcessPort(emu), clock), emu


@pytest.mark.parametrize(("firmware", "torque_on"), [(46, True), (45, True), (44, False)])
def test_emulated_servo_models_torque_on_by_goal_update(firmware: int, torque_on: bool) -> None:
    servo = EmulatedServo(1, 1060, VirtualClock(), firmware=firmware)
    assert servo.write(ct.DRIVE_MODE.address, bytes([0x08])) == 0  # EEPROM: torque is off
    assert not servo.torque_on
    assert servo.write(ct.GOAL_POSITION.address, (2100).to_bytes(4, "little")) == 0
    assert servo.torque_on is torque_on


def test_connect_refuses_torque_on_by_goal_update() -> None:
    arm, emu = make_arm(drive_mode=0x08)
    with pytest.raises(ConfigMismatchError, match="Torque On by Goal Update"):
        arm.connect()
    assert all(not s.torque_on for s in emu.servos.values())  # refused before torque on


def test_bit_3_means_nothing_before_firmware_45() -> None:
    arm, _emu = make_arm(drive_mode=0x08, firmware=44)
    arm.connect()
    arm.close()


def test_close_after_an_emergency_stop_leaves_torque_off() -> None:
    arm, emu = make_arm()
    arm.connect()
    arm.move_to(direction_from_az_el(30, 40))
    arm.emergency_stop()
    for servo in emu.servos.values():  # even if bit 3 were set behind our back
        servo.table[ct.DRIVE_MODE.address] = 0x08
    arm.close()
    assert all(not s.torque_on for s in emu.servos.values())


def test_a_lost_or_corrupt_status_packet_is_retried_once_on_reads() -> None:
    arm, emu = make_arm()
    arm.connect()
    emu.corrupt_next_replies = 1
    reached = arm.move_to(direction_from_az_el(60, 30))  # its reads meet one corrupt reply
    assert reached is not None
    emu.corrupt_next_replies = 2  # twice in a row: a real fault, named
    with pytest.raises(CommunicationError, match="COMM_RX_CORRUPT"):
        arm.joint_ticks()
