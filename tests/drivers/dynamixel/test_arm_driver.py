"""The arm driver over the real dynamixel_sdk against emulated servos."""

from __future__ import annotations

import dynamixel_sdk as sdk
import numpy as np
import pytest
from dxl_support import arm_settings
from pydantic import ValidationError

from rti_rig.core.arm_motion import move_time_s
from rti_rig.core.clock import VirtualClock
from rti_rig.core.devices import LightCarrier
from rti_rig.core.geometry import angle_between_deg, direction_from_az_el
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.faults import (
    CommunicationError,
    ConfigMismatchError,
    DynamixelError,
    HardwareFaultError,
    MoveTimeoutError,
    SafetyViolation,
    UnreachableError,
)
from rti_rig.simulator.dynamixel_emulator import RESTART_S, InProcessPort, emulator_for_arm
from rti_rig.simulator.dynamixel_pty import PtyServoServer

#: How far a joint at the test arm's profile velocity travels while a position read's status
#: and the hold's write cross the bus at 57600 baud (about 5 ms: a few ticks), with margin.
BUS_TRAVEL_TICKS = 12


def make_arm(**overrides):
    settings = arm_settings(**overrides)
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    return DynamixelArm(settings, InProcessPort(emu), clock), emu, clock


def test_is_a_light_carrier_and_moves_where_asked() -> None:
    arm, emu, _clock = make_arm()
    assert isinstance(arm, LightCarrier)
    arm.connect()
    # connect synchronised the servo-side position limits with the config
    assert emu.servos[1].get(ct.MIN_POSITION_LIMIT) == arm.settings.azimuth.tick_limits[0]
    assert emu.servos[2].get(ct.MAX_POSITION_LIMIT) == arm.settings.elevation.tick_limits[1]
    for az, el in [(30, 40), (-120, 20), (160, 70), (0, 5)]:
        target = direction_from_az_el(az, el)
        reached = arm.move_to(target)
        assert angle_between_deg(reached, target) < 0.2  # a tick is 0.088 deg
        ticks = emu.joint_positions()
        assert angle_between_deg(arm.kin.direction_of_ticks(ticks[1], ticks[2]), target) < 0.2
    held = tuple(round(v) for v in emu.joint_positions().values())
    arm.close()
    # "hold" policy: torque stays on, and close never moves the arm (parking is policy's call)
    assert emu.servos[1].get(ct.TORQUE_ENABLE) == 1
    assert tuple(round(v) for v in emu.joint_positions().values()) == held
    assert held != arm.kin.ticks_of_pose(0.0, 10.0)
    arm.close()  # twice is fine


def test_release_on_close_releases_torque_only_at_the_park_pose() -> None:
    arm, emu, _clock = make_arm(torque_policy="release_on_close")
    arm.connect()
    arm.move_to(direction_from_az_el(40, 60))
    arm.close()  # stopped mid-band: a limp arm could drop, so it keeps holding
    assert emu.servos[1].get(ct.TORQUE_ENABLE) == 1 and emu.servos[2].get(ct.TORQUE_ENABLE) == 1
    arm.connect()
    arm.park()
    arm.close()  # parked: released
    assert emu.servos[1].get(ct.TORQUE_ENABLE) == 0 and emu.servos[2].get(ct.TORQUE_ENABLE) == 0


def test_move_time_matches_the_motion_model() -> None:
    arm, _emu, clock = make_arm(settle_time_s=0.0, poll_interval_s=0.005)
    arm.connect()
    a, b = direction_from_az_el(-100, 10), direction_from_az_el(120, 60)
    arm.move_to(a)
    t0 = clock.now()
    arm.move_to(b)
    measured = clock.now() - t0
    model = move_time_s(a, b, arm.settings)
    assert model > 1.0
    assert abs(measured - model) <= 0.02 + 0.01 * model  # polling granularity + rounding


def test_unreachable_directions_never_reach_the_bus() -> None:
    arm, emu, _clock = make_arm()
    arm.connect()
    before = len(emu.goal_log)
    for az, el in [(10, 80), (0, 90), (175, 30), (20, -5)]:
        d = direction_from_az_el(az, el)
        assert arm.unreachable_reason(d) is not None
        with pytest.raises(UnreachableError):
            arm.move_to(d)
    for bad in ([0.0, 0.0, 0.0], [np.nan, 0.0, 1.0], [1.0, 2.0]):
        with pytest.raises(UnreachableError):
            arm.move_to(bad)
    assert len(emu.goal_log) == before
    with pytest.raises(SafetyViolation, match="keep-out"):
        arm._send_goal(arm.kin.ticks_of_pose(0.0, 89.0), "test")
    assert len(emu.goal_log) == before


def test_connect_checks_model_mode_and_limits() -> None:
    arm, emu, _ = make_arm()
    emu.servos[2].table[0:2] = (1020).to_bytes(2, "little")
    with pytest.raises(ConfigMismatchError, match="model number 1020"):
        arm.connect()
    arm.close()
    arm, emu, _ = make_arm()
    emu.servos[1].table[ct.OPERATING_MODE.address] = 4
    with pytest.raises(ConfigMismatchError, match="operating mode 4"):
        arm.connect()
    arm, emu, _ = make_arm(sync_position_limits=False)
    with pytest.raises(ConfigMismatchError, match="Position Limit"):
        arm.connect()
    arm, emu, _ = make_arm()
    emu.servos[2].inject_hardware_error(ct.HardwareFault.OVERHEATING)
    with pytest.raises(HardwareFaultError, match="overheating"):
        arm.connect()


def test_arm_outside_limits_at_power_up_is_refused() -> None:
    arm, emu, _ = make_arm()
    emu.servos[1]._profile.start = emu.servos[1]._profile.goal = 4090.0  # beyond +170 deg
    with pytest.raises(SafetyViolation, match="move the arm by hand"):
        arm.connect()
    assert not emu.servos[1].torque_on
    arm, emu, _ = make_arm()
    in_cone = arm.kin.ticks_of_pose(0.0, 80.0)[1]  # cone starts at 75 deg
    emu.servos[2]._profile.start = emu.servos[2]._profile.goal = float(in_cone)
    with pytest.raises(SafetyViolation, match="keep-out cone"):
        arm.connect()
    assert not emu.servos[2].torque_on and emu.goal_log == []


def test_a_pose_refused_at_connect_says_the_torque_as_read() -> None:
    """An arm left holding by a session with torque_policy = "hold" (its servos keep their
    torque after close), then connected with a wider keep-out cone: its pose is refused, and
    the user told to move it by hand. That had said "(torque is off)" of servos holding
    under torque."""
    arm, emu, clock = make_arm(keep_out_half_angle_deg=5.0)
    arm.connect()
    arm.move_to(direction_from_az_el(0.0, 80.0))
    arm.close()  # "hold": torque stays on
    assert emu.servos[1].torque_on and emu.servos[2].torque_on
    wider = DynamixelArm(arm_settings(keep_out_half_angle_deg=15.0), InProcessPort(emu), clock)
    with pytest.raises(SafetyViolation, match="keep-out cone") as info:
        wider.connect()
    said = str(info.value)
    assert "torque is off" not in said
    assert "its torque is ON, as read: servo 1 (azimuth), servo 2 (elevation)" in said
    assert "power off and on" in said
    # a fresh arm powered up inside the cone: its torque is off, and read so
    arm, emu, _ = make_arm()
    in_cone = arm.kin.ticks_of_pose(0.0, 80.0)[1]
    emu.servos[2]._profile.start = emu.servos[2]._profile.goal = float(in_cone)
    with pytest.raises(SafetyViolation, match=r"\(its torque is off, as read\)"):
        arm.connect()


def test_a_servo_that_does_not_answer_is_told_from_what_the_bus_answers() -> None:
    """A configured servo silent at connect. The error had been the SDK's "There is no status
    packet!" with "check power, cabling, id and baud rate" whatever the cause; a broadcast Ping
    (read-only) now tells a wrong id from an unplugged servo and from a wrong baud rate."""
    clock = VirtualClock()
    emu = emulator_for_arm(arm_settings(), clock)  # servos 1 and 2 on the bus
    wrong_id = DynamixelArm(arm_settings(elevation=dict(servo_id=3)), InProcessPort(emu), clock)
    with pytest.raises(DynamixelError) as info:
        wrong_id.connect()
    said = str(info.value)
    assert "no servo with id 3 answers at 57600 baud, but servo 2 (XL430-W250) does" in said
    assert "set servo_id in [arm.dynamixel.elevation]" in said and info.value.servo_id == 3
    assert not wrong_id.commanded

    emu.silent_ids.add(2)  # the elevation servo unplugged: only the azimuth answers
    arm = DynamixelArm(arm_settings(), InProcessPort(emu), clock)
    with pytest.raises(DynamixelError) as info:
        arm.connect()
    said = str(info.value)
    assert "while servo 1 (the azimuth joint) does" in said
    assert "check the elevation servo's cable" in said and "set servo_id" not in said

    emu.silent_ids.clear()
    wrong_baud = DynamixelArm(arm_settings(baudrate=1_000_000), InProcessPort(emu), clock)
    with pytest.raises(DynamixelError) as info:
        wrong_baud.connect()
    said = str(info.value)
    # the servos answer at their factory 57600: that rate is named, with the key to set
    assert "at 1000000 baud (the [arm.dynamixel] baudrate), but servos 1 (XL430-W250)" in said
    assert "set baudrate = 57600 in [arm.dynamixel]" in said
    assert emu.host_baud == 1_000_000  # the port is back at the configured rate
    assert not wrong_baud.commanded

    emu.silent_ids.update({1, 2})  # nothing answers at any rate: power, cabling, protocol
    with pytest.raises(DynamixelError) as info:
        wrong_baud.connect()
    said = str(info.value)
    assert "no servo at all answers a broadcast ping" in said and "at 1000000 baud" in said
    assert "nor at 57600, 115200" in said and "Protocol 2.0" in said


def test_one_servo_at_another_rate_than_the_other_is_named_with_its_rate() -> None:
    """The elevation servo set to 1 Mbps (replaced, or its rate changed alone) beside an
    azimuth at 57600: it had been told to check its cable first, with no word of a rate."""
    clock = VirtualClock()
    emu = emulator_for_arm(arm_settings(), clock)
    emu.servos[2]._set(ct.BAUD_RATE, 3)  # 1 Mbps (e-manual, Baud Rate (8): value 3)
    arm = DynamixelArm(arm_settings(), InProcessPort(emu), clock)
    with pytest.raises(DynamixelError) as info:
        arm.connect()
    said = str(info.value)
    assert info.value.servo_id == 2
    assert "while servo 1 (the azimuth joint) does; the elevation servo answers at 1000000" in said
    assert "set its Baud Rate (address 8) to 57600" in said
    assert emu.host_baud == 57600 and not arm.commanded


def test_fault_during_move_is_named_and_teardown_still_runs() -> None:
    arm, emu, clock = make_arm()
    arm.connect()
    arm.lamp(True)
    real_sleep = clock.sleep

    def sleep_then_overload(s: float) -> None:
        real_sleep(s)
        if clock.now() > 0.3:
            emu.servos[1].inject_hardware_error(ct.HardwareFault.OVERLOAD)

    clock.sleep = sleep_then_overload  # type: ignore[method-assign]
    with pytest.raises(HardwareFaultError) as info:
        arm.move_to(direction_from_az_el(150, 30))
    assert info.value.fault_names == ["overload"] and info.value.servo_id == 1
    assert emu.servos[2].is_moving()  # the elevation joint is still on its way
    with pytest.raises(
        DynamixelError, match=r"stop incomplete: servo 2 \(elevation\) held"
    ) as stop:
        arm.close()  # stopping a faulted servo fails, loudly, but the port is released
    assert "azimuth" in str(stop.value) and "overload" in str(stop.value)
    assert not arm.lamp_is_on
    # the joint that answered was held where it was, not left to swing on to its goal: at
    # the position its stop read back, a few ticks behind where the hold's write found it
    # (the joint moves on while the read's status and the write cross the bus)
    held, goal = emu.servos[2].position(), emu.servos[2].get(ct.GOAL_POSITION)
    assert abs(held - goal) < BUS_TRAVEL_TICKS
    clock.sleep = real_sleep  # type: ignore[method-assign]
    clock.sleep(5.0)
    assert not emu.servos[2].is_moving()
    assert emu.servos[2].position() == pytest.approx(goal, abs=1.0)  # within the tick read


def test_a_fault_the_servo_does_not_shut_down_for_is_held_not_called_limp() -> None:
    """An input-voltage error (a supply sagging as both joints start) is outside the factory
    Shutdown setting: the servo keeps its torque and drives on to its goal. The error must say
    the joint is still driven, and the stop must hold it — it had been reported limp and left
    swinging on to its goal."""
    arm, emu, clock = make_arm()
    arm.connect()
    real_sleep = clock.sleep

    def sleep_then_sag(s: float) -> None:
        real_sleep(s)
        if clock.now() > 0.3 and not emu.servos[1].hardware_error:
            emu.servos[1].inject_hardware_error(ct.HardwareFault.INPUT_VOLTAGE)

    clock.sleep = sleep_then_sag  # type: ignore[method-assign]
    with pytest.raises(HardwareFaultError) as info:
        arm.move_to(direction_from_az_el(150, 30))
    assert info.value.fault_names == ["input_voltage"] and info.value.torque_on is True
    assert "still ON" in str(info.value) and "limp" not in str(info.value)
    assert emu.servos[1].is_moving() and emu.servos[1].torque_on
    arm.close()  # both joints answer and are held: the stop is complete
    held = {sid: emu.servos[sid].position() for sid in (1, 2)}
    goal = {sid: emu.servos[sid].get(ct.GOAL_POSITION) for sid in (1, 2)}
    clock.sleep = real_sleep  # type: ignore[method-assign]
    clock.sleep(5.0)
    for sid in (1, 2):  # held where its stop read it (see the test above)
        assert not emu.servos[sid].is_moving()
        assert abs(held[sid] - goal[sid]) < BUS_TRAVEL_TICKS
        assert emu.servos[sid].position() == pytest.approx(goal[sid], abs=1.0)


def test_a_shutdown_fault_is_reported_limp_as_read() -> None:
    arm, emu, _clock = make_arm()
    arm.connect()
    emu.servos[1].inject_hardware_error(ct.HardwareFault.OVERLOAD)
    with pytest.raises(HardwareFaultError) as info:
        arm.move_to(direction_from_az_el(20, 40))
    assert info.value.torque_on is False and "limp" in str(info.value)
    with pytest.raises(
        DynamixelError, match=r"stop incomplete: servo 2 \(elevation\) held"
    ) as stop:
        arm.stop()
    # servo 1 is the azimuth: limp, it lets the arm turn about the vertical, not sag
    assert "azimuth" in str(stop.value) and "(the arm turns freely)" in str(stop.value)
    assert "may sag" not in str(stop.value)


def test_a_faulted_servo_whose_torque_cannot_be_read_is_not_called_held() -> None:
    """Found by a review: with Torque Enable unreadable after an alert, the stop wrote a goal
    to the servo and counted it held — while it had shut down, limp."""

    arm, emu, _clock = make_arm()
    arm.connect()
    emu.servos[1].inject_hardware_error(ct.HardwareFault.OVERLOAD)  # torque really off
    real_read = arm._bus.read

    def read(dxl_id, reg, check_alert=True):  # type: ignore[no-untyped-def]
        if reg is ct.TORQUE_ENABLE:
            raise CommunicationError(
                "arm", "COMM_RX_TIMEOUT", f"read {reg.name}", dxl_id, sdk.COMM_RX_TIMEOUT
            )
        return real_read(dxl_id, reg, check_alert)

    arm._bus.read = read  # type: ignore[method-assign]
    with pytest.raises(
        DynamixelError, match=r"stop incomplete: servo 2 \(elevation\) held"
    ) as stop:
        arm.stop()
    text = str(stop.value)
    assert "azimuth" in text and "could not be read" in text
    assert "servo 1 (azimuth) held" not in text


def test_a_stop_holds_an_arm_found_inside_the_keep_out_cone() -> None:
    """A hold is no move: an arm found inside the cone (an overshoot, a push by hand) is held
    where it is. The stop had sent its hold through the move gate, which refused it, and left
    both joints on their way."""
    arm, emu, _clock = make_arm()
    arm.connect()
    in_cone = arm.kin.ticks_of_pose(0.0, 80.0)[1]  # the cone starts at 75°
    emu.servos[2]._profile.start = emu.servos[2]._profile.goal = float(in_cone)
    before = len(emu.goal_log)
    arm.stop()
    assert (2, in_cone) in emu.goal_log[before:]


def test_stalled_move_times_out_and_stops() -> None:
    # a short timeout needs a short arm: the config refuses one below its longest move
    arm, emu, clock = make_arm(move_timeout_s=2.0, azimuth=dict(min_deg=-20.0, max_deg=20.0))
    arm.connect()
    emu.servos[2].table[ct.TORQUE_ENABLE.address] = 0  # stalls: goal accepted, no motion
    with pytest.raises(MoveTimeoutError, match="not in position"):
        arm.move_to(direction_from_az_el(0, 60))
    assert clock.now() < 3.0


def test_a_move_timeout_names_the_joint_left_short_and_a_torque_found_off() -> None:
    """A servo that restarted (a dip in its supply: RAM back to its initial values, torque
    off, no Hardware Error left) takes the next goal and does not move. The timeout had said
    "goal (a, b), present (c, d) ticks; check for an obstruction": not which servo stayed
    behind, nor that its torque was off."""
    arm, emu, clock = make_arm()
    arm.connect()
    arm.move_to(direction_from_az_el(0, 20))
    emu.servos[2].reboot()  # the elevation servo restarts between two moves
    clock.sleep(RESTART_S)  # and answers again (silent while it restarts)
    with pytest.raises(MoveTimeoutError) as info:
        arm.move_to(direction_from_az_el(0, 60))
    said = str(info.value)
    assert info.value.servo_id == 2
    # limp after its restart, the loaded elevation joint fell from 20 deg to its lower stop
    # during the move's timeout (the emulated arm sags with torque off)
    assert "servo 2: not in position" in said and "the elevation joint was at 0.0 deg" in said
    assert "goal 60.0 deg" in said and "its torque is off" in said and "supply" in said
    assert "obstruction" not in said


def test_a_blocked_joint_s_timeout_names_it_and_the_obstruction() -> None:
    arm, emu, _ = make_arm()
    arm.connect()
    emu.servos[1]._start_move = lambda goal: None  # type: ignore[method-assign]  # blocked
    with pytest.raises(MoveTimeoutError) as info:
        arm.move_to(direction_from_az_el(90, 10))
    said = str(info.value)
    assert info.value.servo_id == 1
    assert "the azimuth joint was at 0.0 deg, goal 90.0 deg" in said and "obstruction" in said
    assert "torque is off" not in said


def test_a_timeout_shorter_than_the_arm_s_longest_move_is_refused() -> None:
    """A 2 rpm azimuth across -170..170 deg takes about 28 s: with a 20 s timeout, a session
    that asked for that swing stopped there, after its first images ("not in position after
    20.0 s ... check for an obstruction")."""
    with pytest.raises(ValidationError, match=r"move_timeout_s = 20 s is shorter") as info:
        arm_settings(move_timeout_s=20.0, azimuth=dict(profile_velocity_rpm=2.0))
    said = str(info.value)
    assert "azimuth joint across its range (-170..170 deg)" in said
    assert "raise move_timeout_s to 42 or more" in said
    arm_settings(move_timeout_s=30.0, azimuth=dict(profile_velocity_rpm=2.0))  # enough


def test_emergency_stop_and_lamp_on_servo_led() -> None:
    arm, emu, _ = make_arm(lamp="servo_led", lamp_servo_id=2)
    arm.connect()
    arm.lamp(True)
    assert emu.servos[2].get(ct.LED) == 1
    arm.emergency_stop()
    assert not emu.servos[1].torque_on and not emu.servos[2].torque_on
    assert not arm.lamp_is_on and emu.servos[2].get(ct.LED) == 0  # said off, and off


def test_an_emergency_stop_says_torque_off_confirmed_only_when_read_back() -> None:
    """The torque-off is a broadcast, which no servo answers: the stop reads each servo's
    Torque Enable back and says "torque off confirmed" only when every one reads 0. It had
    returned nothing, the arm taken for limp whatever reached it."""
    arm, emu, _ = make_arm()
    arm.connect()
    said = arm.emergency_stop()
    assert not emu.servos[1].torque_on and not emu.servos[2].torque_on
    assert said.startswith("torque off confirmed"), said
    assert "servo 1 (azimuth), servo 2 (elevation)" in said, said


def test_an_emergency_stop_whose_broadcast_is_lost_names_the_joints_still_held() -> None:
    """The torque-off packet lost on the line (noise on a long cable): both servos keep their
    torque on and read it back so; the stop names them as still holding and never says
    confirmed."""
    arm, emu, _ = make_arm()
    arm.connect()
    port = arm._bus.port
    deliver = port.writePort
    # Protocol 2.0: id 0xFE (broadcast), length 6, WRITE (3), address 64 (2 bytes), value 0
    torque_off = bytes([0xFE, 0x06, 0x00, 0x03, ct.TORQUE_ENABLE.address, 0x00, 0x00])

    def loses_the_torque_off(packet):  # type: ignore[no-untyped-def]
        if bytes(packet)[4:11] == torque_off:
            return len(packet)  # sent, never arrives
        return deliver(packet)

    port.writePort = loses_the_torque_off
    said = arm.emergency_stop()
    assert emu.servos[1].torque_on and emu.servos[2].torque_on  # the packet never arrived
    assert "confirmed" not in said, said
    assert "reads back ON from servo 1 (azimuth), servo 2 (elevation)" in said, said
    assert "switch the servos' power off" in said, said


@pytest.mark.parametrize("transport", [pytest.param("pty", marks=pytest.mark.pty), "inprocess"])
def test_an_emergency_stop_with_a_servo_unplugged_says_it_was_not_read_back(
    transport: str,
) -> None:
    """The elevation servo unplugged: its Torque Enable read goes unanswered. The stop
    returns (the reads are bounded by the SDK's packet timeout, over a real pty too) and says
    that servo was not read back, never that torque is off."""
    from rti_rig.simulator.dynamixel_emulator import emulated_arm_port

    settings = arm_settings()
    clock = VirtualClock()
    with emulated_arm_port(settings, clock, transport) as (port, emu):
        arm = DynamixelArm(settings, port, clock)
        arm.connect()
        emu.silent_ids.add(2)
        said = arm.emergency_stop()
    assert "confirmed" not in said, said
    assert "not read back from servo 2 (elevation) (no answer)" in said, said
    assert "servo 1" not in said, said  # read back 0: not named as unknown or held


def test_settings_errors_name_the_problem() -> None:
    with pytest.raises(ValidationError, match="keep-out cone"):
        arm_settings(park_elevation_deg=80.0)
    with pytest.raises(ValidationError, match=r"outside 0\.\.4095"):
        arm_settings(azimuth=dict(min_deg=-200.0))
    with pytest.raises(ValidationError, match="share servo_id"):
        arm_settings(elevation=dict(servo_id=1))
    with pytest.raises(ValidationError, match="extra"):
        arm_settings(speed=3)
    with pytest.raises(ValidationError, match="not a supported"):
        arm_settings(azimuth=dict(model_number=12))


@pytest.mark.pty
def test_dry_run_with_the_real_sdk_over_a_pty() -> None:
    settings = arm_settings(
        azimuth=dict(operating_mode="extended_position", min_deg=-360.0, max_deg=360.0)
    )
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    with PtyServoServer(emu) as server:
        arm = DynamixelArm(settings, server.port_handler(), clock)
        with arm:
            reached = [arm.move_to(direction_from_az_el(az, 30)) for az in (170, -170, 10)]
        # multi-turn: 170 -> -170 deg goes the short way, through 180 (joint 190 deg)
        az_ticks = [g for i, g in emu.goal_log if i == 1]
        assert max(az_ticks) > arm.kin.ticks_of_pose(180.0, 30.0)[0]
    for az, d in zip((170, -170, 10), reached, strict=True):
        assert angle_between_deg(d, direction_from_az_el(az, 30)) < 0.2
    assert clock.now() > 1.0  # emulator time passed; the wall clock did not wait for it
    assert np.isfinite(clock.now())


@pytest.mark.parametrize("transport", [pytest.param("pty", marks=pytest.mark.pty), "inprocess"])
def test_emulated_arm_port_dry_run(transport: str) -> None:
    from rti_rig.simulator.dynamixel_emulator import emulated_arm_port

    settings = arm_settings()
    clock = VirtualClock()
    with emulated_arm_port(settings, clock, transport) as (port, emu):
        arm = DynamixelArm(settings, port, clock)
        with arm:
            reached = arm.move_to(direction_from_az_el(45, 45))
            from rti_rig.simulator.dynamixel_emulator import lamp_direction

            assert angle_between_deg(lamp_direction(emu, settings), reached) < 0.01
            # mid-move the lamp is between start and goal
            start = lamp_direction(emu, settings)
            goal = direction_from_az_el(-45, 30)
            arm._send_goal(arm.kin.ticks_of_pose(-45.0, 30.0), "test")
            arm.joint_ticks()  # a round trip: the pty server has taken the (unanswered) goal
            clock.sleep(0.3)
            mid = lamp_direction(emu, settings)
            assert angle_between_deg(mid, start) > 1.0 and angle_between_deg(mid, goal) > 1.0
        assert not port.is_open


def test_reboot_after_fault_then_home() -> None:
    arm, emu, _ = make_arm()
    arm.connect()
    emu.servos[1].inject_hardware_error(ct.HardwareFault.ELECTRICAL_SHOCK)
    with pytest.raises(HardwareFaultError, match="electrical shock"):
        arm.move_to(direction_from_az_el(90, 30))
    arm.reboot()
    assert emu.servos[1].hardware_error == 0 and emu.servos[1].torque_on
    arm.move_to(direction_from_az_el(90, 30))
    arm.home()
    park = arm.kin.ticks_of_pose(0.0, 10.0)
    assert tuple(round(v) for v in emu.joint_positions().values()) == park
    arm.close()


def test_reboot_waits_for_each_servo_to_restart_before_reconnecting() -> None:
    """A servo acknowledges a Reboot at once, then answers nothing while it restarts (~0.4 s
    measured on XC330s). ``reboot()`` had reconnected at once: its first ping went unanswered
    and the arm was said to have a power, cabling, id or baud-rate fault."""
    arm, emu, clock = make_arm()
    arm.connect()
    emu.servos[2].restart_s = 1.2  # a slower restart than the default
    started = clock.now()
    arm.reboot()
    assert clock.now() - started >= 1.2  # it waited for the servo, on the arm's clock
    assert all(s.torque_on for s in emu.servos.values())


def test_a_servo_that_does_not_come_back_from_a_reboot_is_named() -> None:
    arm, emu, clock = make_arm()
    arm.connect()
    emu.servos[2].restart_s = 60.0  # never back within the driver's wait
    started = clock.now()
    with pytest.raises(CommunicationError) as info:
        arm.reboot()
    said = str(info.value)
    assert info.value.servo_id == 2 and "servo 2" in said
    assert "elevation joint's servo answered no ping within 3 s of its Reboot" in said, said
    assert "power off and on" in said
    assert clock.now() - started < 4.0  # bounded


@pytest.mark.parametrize("level", [0, 1])
def test_a_servo_that_answers_no_write_is_refused_before_any_write(level: int) -> None:
    """A servo left at Status Return Level 1 by another program answers pings and reads but
    no write: the connect's first write (torque off) timed out with "check power, cabling, id
    and baud rate"; at level 0 its first read did. Both are named, before anything is
    written."""
    arm, emu, _ = make_arm()
    emu.servos[2].table[ct.STATUS_RETURN_LEVEL.address] = level
    with pytest.raises(DynamixelError) as info:
        arm.connect()
    said = str(info.value)
    assert info.value.servo_id == 2 and "elevation joint's servo" in said, said
    assert "Status Return Level (address 68)" in said and "power off and on" in said
    assert (f"is {level}:" if level else "is most likely 0") in said
    assert "cabling" not in said
    assert not arm.commanded  # refused before any write


def test_settings_from_a_rig_toml_table() -> None:
    import tomllib

    from rti_rig.drivers.dynamixel.settings import ArmSettings

    text = """
    [arm]
    port = "/dev/ttyUSB0"
    baudrate = 1000000
    keep_out_half_angle_deg = 12.0
    park_azimuth_deg = 0.0
    park_elevation_deg = 15.0
    [arm.azimuth]
    servo_id = 1
    model_number = 1020
    operating_mode = "extended_position"
    zero_offset_ticks = 2048
    min_deg = -360.0
    max_deg = 360.0
    [arm.elevation]
    servo_id = 2
    model_number = 1020
    zero_offset_ticks = 1024
    direction = -1
    min_deg = 0.0
    max_deg = 85.0
    """
    s = ArmSettings.model_validate(tomllib.loads(text)["arm"])
    assert s.azimuth.mode == ct.OperatingMode.EXTENDED_POSITION
    assert s.elevation.tick_limits == (57, 1024)  # direction -1: 85 deg is below the zero


def test_the_documented_rig_config_validates_and_dry_runs() -> None:
    """docs/protocols/dynamixel-arm.md points to the shipped simulated_arm.toml as the complete
    example of the arm's tables: its ``[arm.dynamixel]`` table is ``ArmSettings`` as is, its
    top-level ``backend`` and ``[arm] transport`` are what the doc says, and it drives the
    emulated servos."""
    import tomllib
    from pathlib import Path

    from rti_rig.drivers.dynamixel.settings import ArmSettings

    repo = Path(__file__).resolve().parents[3]
    doc = (repo / "docs" / "protocols" / "dynamixel-arm.md").read_text(encoding="utf-8")
    for said in ("[arm.dynamixel]", "rig_configs/simulated_arm.toml", 'backend = "emulated"'):
        assert said in doc, said
    config = tomllib.loads((repo / "rig_configs" / "simulated_arm.toml").read_text())
    assert (config["backend"], config["arm"]["transport"]) == ("emulated", "pty")
    settings = ArmSettings.model_validate(config["arm"]["dynamixel"])
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    with DynamixelArm(settings, InProcessPort(emu), clock) as arm:
        arm.move_to(direction_from_az_el(-90, 45))
    assert clock.now() > 0.5


class _Interrupt(BaseException):
    """What the stop's signal handler raises in the main thread (EmergencyStop)."""


def _interrupt_next_read(port: InProcessPort) -> None:
    """The next reply is interrupted half-read, as a Ctrl-C inside the SDK's rxPacket would."""
    read = port.readPort

    def once(length: int) -> bytes:
        port.readPort = read  # type: ignore[method-assign]
        read(min(length, 3))
        raise _Interrupt

    port.readPort = once  # type: ignore[method-assign]


def test_a_stop_reaches_the_servos_after_an_exchange_was_interrupted() -> None:
    """A Ctrl-C raised inside an SDK exchange left the port marked in use: every later packet,
    the stop's hold and torque-off among them, failed with COMM_PORT_BUSY and the arm went on
    to its goal ("it may still be moving")."""
    settings = arm_settings()
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    port = InProcessPort(emu)
    arm = DynamixelArm(settings, port=port, clock=clock)
    arm.connect()
    goal = arm.kin.ticks_of_pose(90.0, 30.0)
    arm._bus.write(1, ct.GOAL_POSITION, goal[0])  # on its way
    _interrupt_next_read(port)
    with pytest.raises(_Interrupt):
        arm._bus.read(1, ct.PRESENT_POSITION)
    before = len(emu.goal_log)
    arm.stop()  # raised nothing: its packets got out
    assert {sid for sid, _ in emu.goal_log[before:]} == {1, 2}  # both joints held
    arm.emergency_stop()
    assert not emu.servos[1].torque_on and not emu.servos[2].torque_on


@pytest.mark.pty
def test_a_late_reply_of_an_interrupted_read_is_not_the_next_answer() -> None:
    """Over the real SDK and a pty, whose emulator sends a reply only once the host reads: a
    read interrupted before its first byte leaves its status packet to come. It is discarded,
    not read as the next command's answer (a 1-byte LED read taken for the 4-byte position)."""
    from rti_rig.drivers.dynamixel.bus import DxlBus

    clock = VirtualClock()
    emu = emulator_for_arm(arm_settings(), clock)
    with PtyServoServer(emu) as server:
        port = server.port_handler()
        bus = DxlBus(port, "arm")
        bus.open(57600)
        try:
            position = bus.read(1, ct.PRESENT_POSITION)
            emu.servos[1].table[ct.LED.address] = 1
            read = port.readPort

            def interrupted(length: int) -> bytes:  # before any byte of the reply is read
                port.readPort = read  # type: ignore[method-assign]
                raise _Interrupt

            port.readPort = interrupted  # type: ignore[method-assign]
            with pytest.raises(_Interrupt):
                bus.read(1, ct.LED)
            assert bus.read(1, ct.PRESENT_POSITION) == position
            assert bus.read(1, ct.LED) == 1
        finally:
            bus.close()


def test_a_connect_that_fails_after_writing_is_not_said_to_have_commanded_nothing() -> None:
    """A connect that failed at servo 2's torque-on had left servo 1 under torque, and the
    check and the stop said "nothing was moved" / "nothing was commanded"."""
    from types import SimpleNamespace

    from rti_rig.app.usecases.safe_state import lights_state
    from rti_rig.core.rig_geometry import ArmGeometry
    from rti_rig.drivers.dynamixel.faults import CommunicationError
    from rti_rig.runtime.arm_check import arm_self_test
    from rti_rig.runtime.lighting import ArmLighting

    arm, emu, clock = make_arm()
    write = arm._bus.write

    def torque_fails_on_2(dxl_id, reg, value, check_alert=True):  # type: ignore[no-untyped-def]
        if reg is ct.TORQUE_ENABLE and dxl_id == 2 and value == 1:
            raise CommunicationError("arm", "lost on the wire", "write Torque Enable", 2)
        return write(dxl_id, reg, value, check_alert)

    arm._bus.write = torque_fails_on_2  # type: ignore[method-assign]
    geometry = ArmGeometry(5.0, 70.0, 15.0, 0.0, 10.0, -170.0, 170.0)
    report = arm_self_test(arm, geometry, clock)
    assert emu.servos[1].torque_on  # what the claim must not deny
    text = " ".join(report.lines())
    assert "nothing was commanded" not in text and "failed part-way" in text
    rig = SimpleNamespace(
        lighting=ArmLighting(arm, config="arm.toml"), loaded=SimpleNamespace(config=None)
    )
    said = lights_state(rig)
    assert "nothing was commanded" not in said and "under torque" in said
    # a port that would not open: nothing was written, and that is said
    never, _, _ = make_arm()
    never._bus.port.openPort = lambda: False  # type: ignore[method-assign]
    report = arm_self_test(never, geometry, clock)
    assert "nothing was commanded: the arm could not be connected" in " ".join(report.lines())
    rig = SimpleNamespace(
        lighting=ArmLighting(never, config="arm.toml"), loaded=SimpleNamespace(config=None)
    )
    assert lights_state(rig) == "nothing was commanded: the arm could not be connected"


def test_a_connect_refused_after_writing_only_limits_is_not_said_to_hold_under_torque() -> None:
    """Fresh servos (factory limits 0..4095) powered up inside the keep-out cone: the connect
    writes the config's limits (torque off, EEPROM), then refuses the pose, saying the torque
    reads off. The check then added "a servo may be holding its position under torque; switch
    the arm's power off", which no write had made so."""
    from rti_rig.core.rig_geometry import ArmGeometry
    from rti_rig.runtime.arm_check import arm_self_test

    arm, emu, clock = make_arm()
    in_cone = arm.kin.ticks_of_pose(0.0, 80.0)[1]
    emu.servos[2]._profile.start = emu.servos[2]._profile.goal = float(in_cone)
    geometry = ArmGeometry(5.0, 70.0, 15.0, 0.0, 10.0, -170.0, 170.0)
    report = arm_self_test(arm, geometry, clock)
    text = " ".join(" ".join(report.lines()).split())
    assert emu.servos[2].get(ct.MAX_POSITION_LIMIT) == arm.settings.elevation.tick_limits[1]
    assert not emu.servos[1].torque_on and not emu.servos[2].torque_on
    assert "(its torque is off, as read)" in text
    assert "under torque" not in text and "switched no servo's torque on" in text
    # the pose read from the servos is no goal: nothing was sent
    assert "elevation position 1934 ticks = 79.980 deg" in text and "goal" not in text


def test_a_port_lost_mid_session_is_a_named_device_error() -> None:
    """The arm's USB adapter unplugged under an exchange: pyserial raises SerialException (an
    OSError) from the SDK's read or write. It had escaped the driver as itself, and the CLI
    printed a Python traceback instead of the stop's outcome and the resume hint."""
    import serial

    settings = arm_settings()
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    port = InProcessPort(emu, name="/dev/ttyUSB0")
    arm = DynamixelArm(settings, port=port, clock=clock)
    arm.connect()

    def gone(*args: object) -> bytes:
        raise serial.SerialException(
            "device reports readiness to read but returned no data (device disconnected or "
            "multiple access on port?)"
        )

    port.writePort = gone  # type: ignore[method-assign]
    port.readPort = gone  # type: ignore[method-assign]
    with pytest.raises(DynamixelError, match=r"port '/dev/ttyUSB0' failed.*U2D2") as info:
        arm.move_to(direction_from_az_el(90, 30))
    assert isinstance(info.value.__cause__, serial.SerialException)
    # the teardown says what it could not do, by name, whatever the step
    with pytest.raises(DynamixelError, match=r"stop incomplete.*port '/dev/ttyUSB0' failed"):
        arm.close()


def test_the_lamp_goes_off_on_a_servo_that_reports_a_fault() -> None:
    """A servo in fault still carries out a Write (the Alert bit is no error number): the
    servo_led lamp's off is done, and said so (it was reported as failed, and the lamp kept
    as on); switching it on again is refused."""
    arm, emu, _ = make_arm(lamp="servo_led", lamp_servo_id=2)
    arm.connect()
    arm.lamp(True)
    emu.inject_hardware_error(2, ct.HardwareFault.OVERLOAD)
    arm.lamp(False)
    assert emu.servos[2].get(ct.LED) == 0 and not arm.lamp_is_on
    with pytest.raises(HardwareFaultError, match="overload"):
        arm.lamp(True)
    assert not arm.lamp_is_on


def test_check_held_after_a_capture_names_a_joint_that_moved_or_faulted() -> None:
    """Read after each capture (the controller keeps no image under a direction the arm no
    longer holds): a joint off its goal (a sag, a bump) and a servo fault are both named."""
    import numpy as np

    arm, emu, _clock = make_arm()
    arm.connect()
    arm.move_to(np.array([0.0, 0.5, 0.8]))
    arm.check_held()  # where it was left: nothing to say
    goal = arm.joint_ticks()[1]
    emu.servos[2]._profile.start = emu.servos[2]._profile.goal = float(goal - 40)  # sagged
    with pytest.raises(DynamixelError, match="the elevation joint moved during the capture"):
        arm.check_held()
    emu.servos[2]._profile.start = emu.servos[2]._profile.goal = float(goal)
    emu.servos[1].inject_hardware_error(ct.HardwareFault.OVERHEATING)
    with pytest.raises(DynamixelError, match="servo 1: hardware fault overheating"):
        arm.check_held()
