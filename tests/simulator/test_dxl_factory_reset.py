"""Factory Reset (0x06) on the emulated servos, sent by the real dynamixel_sdk: the control
table back to the model's factory Initial Values and a restart, keeping the ID (0x01) or the
ID and the Baud Rate (0x02) as the e-manual's Protocol 2.0 page says; 0xFF to the broadcast
ID is not carried out. (The emulator had answered every Factory Reset with an Instruction
Error.)"""

from __future__ import annotations

import dynamixel_sdk as sdk

from rti_rig.core.clock import VirtualClock
from rti_rig.simulator import dynamixel_table as tbl
from rti_rig.simulator.dynamixel_emulator import (
    RESTART_S,
    DynamixelBusEmulator,
    EmulatedServo,
    InProcessPort,
)


def one_servo(dxl_id: int, model: int = 1020):
    """A servo configured as a rig would leave it: extended position, limits, quick replies,
    a profile, torque on, a latched fault."""
    clock = VirtualClock()
    servo = EmulatedServo(dxl_id, model, clock, operating_mode=4, max_position=3000)
    servo._set(tbl.RETURN_DELAY_TIME, 0)
    servo._set(tbl.PROFILE_VELOCITY, 50)
    servo._set(tbl.TORQUE_ENABLE, 1)
    servo.inject_hardware_error(tbl.OVERHEATING_ERROR)
    emu = DynamixelBusEmulator([servo], clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)
    return servo, port, sdk.PacketHandler(2.0), clock


def assert_factory_settings(servo: EmulatedServo) -> None:
    assert servo.get(tbl.OPERATING_MODE) == 3
    assert servo.get(tbl.MAX_POSITION_LIMIT) == 4095
    assert servo.get(tbl.RETURN_DELAY_TIME) == 250
    assert servo.get(tbl.PROFILE_VELOCITY) == 0
    assert not servo.torque_on and servo.hardware_error == 0
    assert servo.get(tbl.FIRMWARE_VERSION) != 0  # not a setting: kept


def test_reset_all_but_the_id_and_baud_rate_keeps_both() -> None:
    servo, port, ph, clock = one_servo(3)
    servo._set(tbl.BAUD_RATE, 3)  # 1 Mbps
    assert port.setBaudRate(1_000_000)
    assert ph.factoryReset(port, 3, 0x02) == (sdk.COMM_SUCCESS, 0)
    assert_factory_settings(servo)
    assert servo.get(tbl.BAUD_RATE) == 3 and servo.dxl_id == 3
    clock.sleep(RESTART_S)  # it restarts, then answers at the same ID and speed
    assert ph.ping(port, 3)[1:] == (sdk.COMM_SUCCESS, 0)


def test_reset_all_but_the_id_brings_the_baud_rate_back_to_57600() -> None:
    servo, port, ph, clock = one_servo(3)
    servo._set(tbl.BAUD_RATE, 3)
    assert port.setBaudRate(1_000_000)
    assert ph.factoryReset(port, 3, 0x01) == (sdk.COMM_SUCCESS, 0)
    assert_factory_settings(servo)
    assert servo.get(tbl.BAUD_RATE) == 1 and servo.dxl_id == 3
    clock.sleep(RESTART_S)
    assert ph.ping(port, 3)[1] != sdk.COMM_SUCCESS  # no longer at 1 Mbps
    assert port.setBaudRate(57600)
    assert ph.ping(port, 3)[1:] == (sdk.COMM_SUCCESS, 0)


def test_reset_all_brings_the_id_back_to_1() -> None:
    servo, port, ph, clock = one_servo(5, model=1060)
    assert ph.factoryReset(port, 5, 0xFF) == (sdk.COMM_SUCCESS, 0)  # answered as ID 5
    assert_factory_settings(servo)
    assert servo.dxl_id == 1 and servo.get(tbl.TEMPERATURE_LIMIT) == 72  # the XL430's
    clock.sleep(RESTART_S)
    assert ph.ping(port, 5)[1] != sdk.COMM_SUCCESS
    assert ph.ping(port, 1)[1:] == (sdk.COMM_SUCCESS, 0)


def test_reset_all_sent_to_every_servo_at_once_is_not_carried_out() -> None:
    servo, port, ph, _clock = one_servo(5)
    ph.factoryReset(port, sdk.BROADCAST_ID, 0xFF)
    assert servo.dxl_id == 5 and servo.get(tbl.OPERATING_MODE) == 4
    assert servo.hardware_error == tbl.OVERHEATING_ERROR  # no restart either
