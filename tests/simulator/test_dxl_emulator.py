"""The emulated servos, driven by the real dynamixel_sdk over a pty and in-process."""

from __future__ import annotations

import dynamixel_sdk as sdk
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2
from rti_rig.drivers.dynamixel.bus import DxlBus
from rti_rig.drivers.dynamixel.faults import (
    CommunicationError,
    HardwareFaultError,
    ServoStatusError,
)
from rti_rig.simulator.dynamixel_emulator import (
    RESTART_S,
    DynamixelBusEmulator,
    EmulatedServo,
    InProcessPort,
)
from rti_rig.simulator.dynamixel_pty import PtyServoServer


def two_servos(clock: VirtualClock, mode: int = 3) -> DynamixelBusEmulator:
    return DynamixelBusEmulator(
        [
            EmulatedServo(1, 1060, clock, operating_mode=mode),
            EmulatedServo(2, 1020, clock, operating_mode=mode, present_ticks=1000),
        ],
        clock,
    )


@pytest.fixture
def pty_bus():
    """The real SDK over a pty, on the server's causal port: no reply wait depends on load."""
    clock = VirtualClock()
    emu = two_servos(clock)
    server = PtyServoServer(emu)
    server.start()
    port = server.port_handler()
    assert port.openPort() and port.setBaudRate(57600)
    try:
        yield port, sdk.PacketHandler(2.0), emu, clock
    finally:
        port.closePort()
        server.stop()


class SlowEmulator(DynamixelBusEmulator):
    """An emulator thread that takes ``delay_s`` of wall time per instruction: what a loaded
    machine does to it when other processes hold the CPUs (or the host holds the GIL)."""

    delay_s = 0.2  # six times the SDK's ~34 ms reply window

    def receive(self, data: bytes) -> bytes:
        import time

        time.sleep(self.delay_s)
        return super().receive(data)


def slow_servos(clock: VirtualClock) -> SlowEmulator:
    return SlowEmulator([EmulatedServo(1, 1060, clock), EmulatedServo(2, 1020, clock)], clock)


@pytest.mark.pty
def test_a_starved_emulator_thread_cannot_make_a_present_servo_time_out() -> None:
    """The cause of the emulated arm's COMM_RX_TIMEOUTs under load, and its fix.

    Negative control: the SDK's own PortHandler times out on a present servo whose emulator
    thread is 200 ms late (its window is wall time). The server's causal port waits for the
    emulator instead, and still reports a really silent servo as COMM_RX_TIMEOUT."""
    clock = VirtualClock()
    emu = slow_servos(clock)
    with PtyServoServer(emu) as server:
        plain = sdk.PortHandler(server.device_path)
        assert plain.openPort()
        ph = sdk.PacketHandler(2.0)
        assert ph.ping(plain, 1)[1] == sdk.COMM_RX_TIMEOUT
        plain.closePort()
    emu = slow_servos(clock)
    with PtyServoServer(emu) as server:
        port = server.port_handler()
        assert port.openPort() and port.setBaudRate(57600)
        assert ph.ping(port, 1) == (1060, sdk.COMM_SUCCESS, 0)
        assert ph.read4ByteTxRx(port, 2, 132) == (2048, sdk.COMM_SUCCESS, 0)
        emu.silent_ids.add(2)
        assert ph.ping(port, 2)[1] == sdk.COMM_RX_TIMEOUT
        group = sdk.GroupSyncRead(port, ph, 132, 4)
        group.addParam(1)
        group.addParam(2)
        assert group.txRxPacket() == sdk.COMM_RX_TIMEOUT  # id 1 answered, id 2 never
        assert ph.ping(port, 1) == (1060, sdk.COMM_SUCCESS, 0)  # nothing stale left behind
        port.closePort()


@pytest.mark.pty
def test_corrupted_crc_and_silence_over_pty(pty_bus) -> None:
    port, ph, emu, _clock = pty_bus
    bus = DxlBus(port, "arm", ph)
    emu.corrupt_next_replies = 1  # one damaged status: a read is idempotent, retried once
    assert bus.read(1, ct.PRESENT_POSITION) == 2048
    assert emu.corrupt_next_replies == 0  # the damaged reply was really sent and met
    emu.corrupt_next_replies = 2  # damaged again on the retry: a named error
    with pytest.raises(CommunicationError, match="COMM_RX_CORRUPT"):
        bus.read(1, ct.PRESENT_POSITION)
    assert bus.read(1, ct.PRESENT_POSITION) == 2048
    emu.silent_ids.add(2)
    with pytest.raises(CommunicationError, match="COMM_RX_TIMEOUT"):
        bus.ping(2)
    emu.silent_ids.clear()
    assert bus.ping(2) == 1020


@pytest.mark.pty
def test_reopening_the_port_starts_from_a_clean_slate() -> None:
    """A status left unread when the port closes is lost with the port (a real one arrives
    within 0.5 ms, long before a reopen), even when the emulator thread is late to send it;
    the causal timeout still tells silence from a reply on its way afterwards."""
    clock = VirtualClock()
    emu = slow_servos(clock)
    emu.delay_s = 0.05
    ph = sdk.PacketHandler(2.0)
    with PtyServoServer(emu) as server:
        port = server.port_handler()
        assert port.openPort() and port.setBaudRate(57600)  # kept for the reopen
        ph.write1ByteTxOnly(port, 1, ct.LED.address, 1)  # its status is never read
        port.closePort()
        assert port.openPort()
        assert ph.read1ByteTxRx(port, 1, ct.LED.address) == (1, sdk.COMM_SUCCESS, 0)
        emu.silent_ids.add(1)
        assert ph.ping(port, 1)[1] == sdk.COMM_RX_TIMEOUT
        port.closePort()


@pytest.mark.pty
def test_a_servo_at_another_baud_rate_answers_nothing() -> None:
    """A servo hears only its own Baud Rate (address 8; factory 57600): the SDK's default
    1 Mbps, or a config's wrong rate, gets no reply (the emulator had answered at any rate, so
    a wrong baud rate in a rig config passed `check`)."""
    clock = VirtualClock()
    ph = sdk.PacketHandler(2.0)
    with PtyServoServer(two_servos(clock)) as server:
        port = server.port_handler()
        assert port.openPort()  # the SDK's default 1 Mbps
        assert ph.ping(port, 1)[1] == sdk.COMM_RX_TIMEOUT
        assert port.setBaudRate(57600)
        assert ph.ping(port, 1)[1] == sdk.COMM_SUCCESS
        port.closePort()
        # read from the pty's own settings: the SDK's plain PortHandler is heard the same way
        plain = sdk.PortHandler(server.device_path)
        assert plain.openPort() and plain.setBaudRate(115200)
        assert ph.ping(plain, 1)[1] == sdk.COMM_RX_TIMEOUT
        plain.closePort()


@pytest.mark.pty
def test_real_sdk_over_pty(pty_bus) -> None:
    port, ph, _emu, _clock = pty_bus
    assert ph.ping(port, 1) == (1060, sdk.COMM_SUCCESS, 0)
    assert ph.ping(port, 2) == (1020, sdk.COMM_SUCCESS, 0)
    assert ph.read4ByteTxRx(port, 2, 132) == (1000, sdk.COMM_SUCCESS, 0)
    # EEPROM locked while torque is on; out-of-limit goal refused
    assert ph.write1ByteTxRx(port, 1, 64, 1) == (sdk.COMM_SUCCESS, 0)
    assert ph.write1ByteTxRx(port, 1, 11, 4) == (sdk.COMM_SUCCESS, 7)
    assert ph.write4ByteTxRx(port, 1, 116, 5000) == (sdk.COMM_SUCCESS, 6)
    # GroupSyncRead answers in the instruction's id order
    group = sdk.GroupSyncRead(port, ph, 132, 4)
    group.addParam(2)
    group.addParam(1)
    assert group.txRxPacket() == sdk.COMM_SUCCESS
    assert group.getData(2, 132, 4) == 1000 and group.getData(1, 132, 4) == 2048


@pytest.mark.pty
def test_motion_follows_profile_in_emulator_time(pty_bus) -> None:
    port, ph, emu, clock = pty_bus
    ph.write4ByteTxRx(port, 1, 112, 100)  # 22.9 rpm
    ph.write4ByteTxRx(port, 1, 108, 10)
    ph.write1ByteTxRx(port, 1, 64, 1)
    ph.write4ByteTxRx(port, 1, 116, 3072)
    assert ph.read1ByteTxRx(port, 1, 122)[0] == 1  # moving
    clock.sleep(0.2)
    mid = emu.joint_positions()[1]
    assert 2048 < mid < 3072
    clock.sleep(10.0)
    assert ph.read1ByteTxRx(port, 1, 122)[0] == 0
    assert ph.read4ByteTxRx(port, 1, 132)[0] == 3072


@pytest.mark.pty
def test_write_no_wait_drains_the_reply_over_pty(pty_bus) -> None:
    """Unicast TxOnly leaves a status the SDK never reads; the bus drains it.

    Negative control first: without the drain the stale reply is taken as the answer to the
    next read of the same servo, every time (a status reaches the host only once it listens,
    the worst case of Return Delay Time), not by a race with the machine's load."""
    port, ph, _emu, _clock = pty_bus
    bus = DxlBus(port, "arm", ph)
    raw_bad = 0
    for i in range(10):
        ph.write1ByteTxOnly(port, 1, ct.LED.address, i % 2)
        try:
            value, result, _ = ph.read4ByteTxRx(port, 1, ct.PRESENT_POSITION.address)
            raw_bad += (result, value) != (sdk.COMM_SUCCESS, 2048)
        except IndexError:  # the SDK itself trips over the empty stale status
            raw_bad += 1
        bus.drain_reply()  # resynchronise before the next round
    assert raw_bad == 10, "the emulator no longer reproduces the unread-status pitfall"
    for i in range(20):
        bus.write_no_wait(1, ct.LED, i % 2)
        assert bus.read(1, ct.PRESENT_POSITION) == 2048
        assert bus.read(1, ct.LED) == i % 2


def test_extended_position_reads_are_signed() -> None:
    clock = VirtualClock()
    emu = two_servos(clock, mode=4)
    port = InProcessPort(emu)
    bus = DxlBus(port, "arm")
    bus.open(57600)
    bus.write(1, ct.TORQUE_ENABLE, 1)
    bus.write(1, ct.GOAL_POSITION, -5000)
    clock.sleep(60.0)
    assert bus.read(1, ct.PRESENT_POSITION) == -5000
    assert bus.read(1, ct.GOAL_POSITION) == -5000


@pytest.mark.parametrize(
    ("fault", "name"),
    [
        (ct.HardwareFault.OVERLOAD, "overload"),
        (ct.HardwareFault.OVERHEATING, "overheating"),
        (ct.HardwareFault.INPUT_VOLTAGE, "input_voltage"),
        (ct.HardwareFault.MOTOR_ENCODER, "motor_encoder"),
        (ct.HardwareFault.ELECTRICAL_SHOCK, "electrical_shock"),
    ],
)
def test_injected_hardware_error_surfaces_by_name(fault, name) -> None:
    clock = VirtualClock()
    emu = two_servos(clock)
    bus = DxlBus(InProcessPort(emu), "arm")
    bus.open(57600)
    emu.inject_hardware_error(2, fault)
    with pytest.raises(HardwareFaultError) as info:
        bus.write(2, ct.LED, 1)
    assert info.value.fault_names == [name] and info.value.servo_id == 2
    assert name.split("_")[0] in str(info.value).lower() and "reboot" in str(info.value)
    # how to reboot, as a user can (the fault stays latched): an overheated servo had only
    # been told to cool down, and was refused again once cool
    assert "; then run rti-rig check RIG.toml --reboot-faulted" in str(info.value)
    assert "or switch the servos' power off and on" in str(info.value)
    bus.reboot(2)
    clock.sleep(RESTART_S)  # silent while it restarts
    bus.write(2, ct.LED, 1)  # cleared


def test_corrupted_crc_and_silence_are_communication_errors() -> None:
    clock = VirtualClock()
    emu = two_servos(clock)
    bus = DxlBus(InProcessPort(emu), "arm")
    bus.open(57600)
    emu.corrupt_next_replies = 1
    assert bus.read(1, ct.PRESENT_POSITION) == 2048  # a read is retried once: no harm done
    emu.corrupt_next_replies = 2
    with pytest.raises(CommunicationError, match="COMM_RX_CORRUPT"):
        bus.read(1, ct.PRESENT_POSITION)
    assert bus.read(1, ct.PRESENT_POSITION) == 2048  # next reply is clean
    emu.corrupt_next_replies = 1
    bus.write(1, ct.LED, 1)  # a write of a value is idempotent: retried once, like a read
    assert emu.servos[1].get(ct.LED) == 1
    emu.drop_next_replies = 1  # its status lost on the wire: the servo acted, the host heard
    bus.write(1, ct.LED, 0)  # nothing (COMM_RX_TIMEOUT); sent again, and the value is there
    assert emu.servos[1].get(ct.LED) == 0 and emu.drop_next_replies == 0
    emu.corrupt_next_replies = 2
    with pytest.raises(CommunicationError, match="COMM_RX_CORRUPT"):
        bus.write(1, ct.LED, 1)  # damaged twice in a row: a named error
    emu.silent_ids.add(2)
    with pytest.raises(CommunicationError, match="servo 2") as info:
        bus.ping(2)
    assert "COMM_RX_TIMEOUT" in str(info.value)


def test_status_errors_are_named() -> None:
    emu = two_servos(VirtualClock())
    bus = DxlBus(InProcessPort(emu), "arm")
    bus.open(57600)
    with pytest.raises(ServoStatusError, match="access error") as info:
        bus.write(1, ct.MODEL_NUMBER, 5)
    assert info.value.error == 7 and "Model Number" in str(info.value)


def test_bulk_read_write_reg_write_action_in_process() -> None:
    clock = VirtualClock()
    emu = two_servos(clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)  # the servos' factory rate
    ph = sdk.PacketHandler(2.0)
    bw = sdk.GroupBulkWrite(port, ph)
    bw.addParam(1, ct.LED.address, 1, [1])
    bw.addParam(2, ct.PROFILE_VELOCITY.address, 4, [50, 0, 0, 0])
    assert bw.txPacket() == sdk.COMM_SUCCESS
    br = sdk.GroupBulkRead(port, ph)
    br.addParam(1, ct.LED.address, 1)
    br.addParam(2, ct.PROFILE_VELOCITY.address, 4)
    assert br.txRxPacket() == sdk.COMM_SUCCESS
    assert br.getData(1, ct.LED.address, 1) == 1
    assert br.getData(2, ct.PROFILE_VELOCITY.address, 4) == 50
    # Reg Write is held until a (broadcast) Action
    assert ph.regWriteTxRx(port, 1, ct.LED.address, 1, [0]) == (sdk.COMM_SUCCESS, 0)
    assert ph.read1ByteTxRx(port, 1, ct.REGISTERED_INSTRUCTION.address)[0] == 1
    assert ph.read1ByteTxRx(port, 1, ct.LED.address)[0] == 1
    DxlBus(port, "arm", ph).action()
    assert ph.read1ByteTxRx(port, 1, ct.LED.address)[0] == 0


def test_emulator_accepts_properly_stuffed_packets() -> None:
    """Other clients stuff FF FF FD in bodies (the e-manual rule); both forms must work."""
    from rti_rig.drivers.dynamixel import protocol2 as p2

    clock = VirtualClock()
    emu = two_servos(clock, mode=4)
    emu.receive(p2.write(1, ct.TORQUE_ENABLE.address, b"\x01"))
    reply = emu.receive(p2.write(1, ct.GOAL_POSITION.address, p2.u32(-131073)))
    assert p2.decode(reply).error == 0
    assert emu.goal_log[-1] == (1, -131073)
    raw = emu.receive(p2.read(1, ct.GOAL_POSITION.address, 4))
    status = p2.decode(raw)
    assert p2.to_signed(int.from_bytes(status.params, "little"), 4) == -131073


def test_a_fault_outside_the_shutdown_setting_alerts_but_leaves_torque_on() -> None:
    """e-manual, Shutdown (63): an error sets its Hardware Error Status bit and the Alert flag;
    torque goes off only for the errors Shutdown selects (factory 0x34: not input voltage)."""
    clock = VirtualClock()
    emu = two_servos(clock)
    bus = DxlBus(InProcessPort(emu), "arm")
    bus.open(57600)
    bus.write(1, ct.TORQUE_ENABLE, 1)
    emu.inject_hardware_error(1, ct.HardwareFault.INPUT_VOLTAGE)
    servo = emu.servos[1]
    assert servo.torque_on and not servo.shut_down
    with pytest.raises(HardwareFaultError) as info:
        bus.read(1, ct.PRESENT_POSITION)
    assert info.value.torque_on is True and "still ON" in str(info.value)
    bus.write(1, ct.GOAL_POSITION, 3000, check_alert=False)
    clock.sleep(5.0)
    assert bus.read(1, ct.PRESENT_POSITION, check_alert=False) == 3000  # it still drives
    # the same error once Shutdown selects it: torque off, motion frozen, no torque-on
    bus.write(2, ct.SHUTDOWN, 0x35)
    bus.write(2, ct.TORQUE_ENABLE, 1)
    emu.inject_hardware_error(2, ct.HardwareFault.INPUT_VOLTAGE)
    assert emu.servos[2].shut_down and not emu.servos[2].torque_on
    with pytest.raises(ServoStatusError, match="result fail"):
        bus.write(2, ct.TORQUE_ENABLE, 1)
    with pytest.raises(HardwareFaultError) as info:
        bus.read(2, ct.PRESENT_POSITION)
    assert info.value.torque_on is False and "limp" in str(info.value)
    bus.reboot(2)
    clock.sleep(RESTART_S)  # silent while it restarts
    bus.write(2, ct.TORQUE_ENABLE, 1)  # a reboot lifts the shutdown


def test_one_write_may_set_several_items_but_never_part_of_one() -> None:
    """e-manual, Protocol 2.0: a Write sets consecutive bytes from its address, so one packet
    may carry Profile Acceleration, Profile Velocity and Goal Position (108..119) and the servo
    moves with that profile; writing only part of an item is a Data Length Error ("only use 2
    bytes of a item that has been defined as 4 bytes"), and a refused Write changes nothing.
    The emulator had refused the first (modelled only on the packets our driver sends) and
    accepted the second."""
    clock = VirtualClock()
    emu = two_servos(clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)
    ph = sdk.PacketHandler(2.0)
    assert ph.write1ByteTxRx(port, 1, ct.TORQUE_ENABLE.address, 1) == (sdk.COMM_SUCCESS, 0)
    block = [*(20).to_bytes(4, "little"), *(40).to_bytes(4, "little")]
    block += list((3000).to_bytes(4, "little"))
    assert ph.writeTxRx(port, 1, ct.PROFILE_ACCELERATION.address, 12, block) == (
        sdk.COMM_SUCCESS,
        0,
    )
    assert ph.read4ByteTxRx(port, 1, ct.PROFILE_VELOCITY.address)[0] == 40
    assert emu.servos[1].is_moving()
    clock.sleep(60.0)
    assert ph.read4ByteTxRx(port, 1, ct.PRESENT_POSITION.address)[0] == 3000
    # two bytes of the 4-byte Profile Velocity: refused, nothing written
    assert ph.writeTxRx(port, 1, ct.PROFILE_VELOCITY.address, 2, [7, 0]) == (
        sdk.COMM_SUCCESS,
        0x05,
    )
    # a Write from Profile Velocity's third byte into Goal Position: refused as a whole
    assert ph.writeTxRx(port, 1, ct.PROFILE_VELOCITY.address + 2, 6, [0, 0, 0, 8, 0, 0]) == (
        sdk.COMM_SUCCESS,
        0x05,
    )
    assert ph.read4ByteTxRx(port, 1, ct.PROFILE_VELOCITY.address)[0] == 40
    assert ph.read4ByteTxRx(port, 1, ct.GOAL_POSITION.address)[0] == 3000
    assert not emu.servos[1].is_moving()


def test_in_position_means_arrived_at_the_goal_not_merely_stopped() -> None:
    """e-manual, Moving Status (123) bit 0 In-Position: "whether or not the DYNAMIXEL has
    arrived to the desired Goal Position". A servo shut down by an overload mid-move stops
    short of its goal: it is not in position (the emulator had said it was, as soon as no
    profile ran); once it holds a goal it has reached, it is."""
    clock = VirtualClock()
    emu = two_servos(clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)
    ph = sdk.PacketHandler(2.0)

    def moving_status() -> int:
        value, result, _error = ph.read1ByteTxRx(port, 1, ct.MOVING_STATUS.address)
        assert result == sdk.COMM_SUCCESS
        return value

    assert ph.write1ByteTxRx(port, 1, ct.TORQUE_ENABLE.address, 1)[0] == sdk.COMM_SUCCESS
    assert moving_status() & 0x03 == 0x01  # holding where it is: arrived
    assert ph.write4ByteTxRx(port, 1, ct.PROFILE_VELOCITY.address, 40)[0] == sdk.COMM_SUCCESS
    assert ph.write4ByteTxRx(port, 1, ct.GOAL_POSITION.address, 3000)[0] == sdk.COMM_SUCCESS
    clock.sleep(0.2)
    assert moving_status() & 0x03 == 0x02  # profile ongoing, not arrived
    emu.inject_hardware_error(1, ct.HardwareFault.OVERLOAD)  # factory Shutdown selects it
    clock.sleep(30.0)
    present = ph.read4ByteTxRx(port, 1, ct.PRESENT_POSITION.address)[0]
    assert 2048 < present < 3000
    assert moving_status() & 0x03 == 0x00  # stopped short: neither moving nor in position
    emu.servos[1].reboot()
    clock.sleep(RESTART_S)  # silent while it restarts
    assert ph.write1ByteTxRx(port, 1, ct.TORQUE_ENABLE.address, 1)[0] == sdk.COMM_SUCCESS
    clock.sleep(1.0)
    assert moving_status() & 0x03 == 0x01  # torque-on holds the present position: arrived


def test_a_reboot_restores_the_ram_area_as_at_power_on() -> None:
    """e-manual: RAM is reset to its initial values when the power is reset, and the Reboot
    instruction is the software form of that. The emulator's reboot had cleared only the
    hardware error, torque and LED, keeping the profile a driver had written."""
    clock = VirtualClock()
    emu = two_servos(clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)
    ph = sdk.PacketHandler(2.0)
    for reg, value in (
        (ct.PROFILE_VELOCITY, 50),
        (ct.PROFILE_ACCELERATION, 20),
        (ct.LED, 1),
        (ct.TORQUE_ENABLE, 1),
    ):
        write = {1: ph.write1ByteTxRx, 4: ph.write4ByteTxRx}[reg.size]
        assert write(port, 1, reg.address, value) == (sdk.COMM_SUCCESS, 0)
    assert ph.regWriteTxRx(port, 1, ct.LED.address, 1, [0]) == (sdk.COMM_SUCCESS, 0)
    emu.inject_hardware_error(1, ct.HardwareFault.OVERHEATING)
    assert ph.reboot(port, 1) == (sdk.COMM_SUCCESS, 0)
    servo = emu.servos[1]
    assert servo.get(ct.PROFILE_VELOCITY) == 0 and servo.get(ct.PROFILE_ACCELERATION) == 0
    assert servo.get(ct.LED) == 0 and not servo.torque_on and servo.hardware_error == 0
    assert servo.get(ct.STATUS_RETURN_LEVEL) == 2  # the model's initial value
    assert servo.get(ct.REGISTERED_INSTRUCTION) == 0
    assert servo.get(ct.GOAL_POSITION) == round(servo.position())
    assert servo.get(ct.MIN_POSITION_LIMIT) == 0  # EEPROM kept
    emu.set_input_voltage(1, 200)  # 20 V: above the XL430's 14 V limit, and still there
    clock.sleep(RESTART_S)  # silent while it restarts
    assert ph.reboot(port, 1)[0] == sdk.COMM_SUCCESS
    assert servo.hardware_error == ct.HardwareFault.INPUT_VOLTAGE


def test_a_servo_switched_to_protocol_1_does_not_answer_protocol_2() -> None:
    """An X-series servo whose Protocol Type (13) is 1 speaks Protocol 1.0 only (e-manual,
    Protocol Compatibility Table). The emulator had answered it in 2.0 all the same, so a
    servo left in 1.0 by another controller passed a dry run that fails on the rig."""
    emu = two_servos(VirtualClock())
    bus = DxlBus(InProcessPort(emu), "arm")
    bus.open(57600)
    bus.write(2, ct.PROTOCOL_TYPE, 1)  # EEPROM, torque off: accepted, answered in 2.0
    with pytest.raises(CommunicationError, match="COMM_RX_TIMEOUT"):
        bus.ping(2)
    assert bus.scan() == {1: 1060}  # nor does it answer a broadcast ping
    assert bus.ping(1) == 1060


def test_the_arms_loaded_elevation_joint_falls_to_its_stop_once_its_torque_goes_off() -> None:
    """A servo with its torque off is back-driven by its load; the emulated arm had frozen
    where it was, so a sag under an overload was never seen through ``run``. The elevation
    joint now falls to its lower limit at SAG_DEG_PER_S (an assumption); the azimuth joint,
    which carries no load against gravity, stays; a joint never driven stays at rest."""
    from rti_rig.simulator.dynamixel_emulator import (
        SAG_DEG_PER_S,
        arm_settings_of,
        emulator_for_arm,
    )

    settings, _ = arm_settings_of(None)
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    azimuth, elevation = emu.servos[1], emu.servos[2]
    rest = elevation.position()
    clock.sleep(5.0)
    assert elevation.position() == rest  # resting at park, never driven: not moved
    for servo in (azimuth, elevation):
        servo.table[ct.TORQUE_ENABLE.address] = 1
    held = elevation.position()
    emu.inject_hardware_error(2, ct.HardwareFault.OVERLOAD)  # shuts down: torque off
    emu.inject_hardware_error(1, ct.HardwareFault.OVERLOAD)
    clock.sleep(0.5)
    per_s = SAG_DEG_PER_S * ct.TICKS_PER_REV / 360.0
    assert elevation.position() == pytest.approx(held - 0.5 * per_s)
    assert azimuth.position() == pytest.approx(azimuth.get(ct.GOAL_POSITION))
    clock.sleep(60.0)
    stop = settings.elevation.zero_offset_ticks  # 0 deg, the lower limit of the shipped arm
    assert elevation.position() == pytest.approx(stop)


def test_moving_is_a_profile_or_a_speed_above_the_moving_threshold() -> None:
    """e-manual, Moving (122): 1 while a profile runs after a Goal Position update, otherwise
    1 only when |Present Velocity| exceeds Moving Threshold (24); Moving Status (123) bit 1 is
    the profile. A limp joint falling under its load runs no profile: at the assumed sag
    rate (about 7 velocity units) it is below the factory threshold of 10 and reads Moving 0
    though it moves; with the threshold lowered it reads 1. The emulator had reported its own
    motion as Moving and "profile ongoing" whatever the threshold."""
    from rti_rig.simulator.dynamixel_emulator import arm_settings_of, emulator_for_arm

    settings, _ = arm_settings_of(None)
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)
    ph = sdk.PacketHandler(2.0)

    def read(reg: ct.Register) -> int:
        read_n = {1: ph.read1ByteTxRx, 4: ph.read4ByteTxRx}[reg.size]
        value, result, _error = read_n(port, 2, reg.address)
        assert result == sdk.COMM_SUCCESS
        return p2.to_signed(value, reg.size)

    assert ph.write1ByteTxRx(port, 2, ct.TORQUE_ENABLE.address, 1)[0] == sdk.COMM_SUCCESS
    assert ph.write4ByteTxRx(port, 2, ct.PROFILE_VELOCITY.address, 40)[0] == sdk.COMM_SUCCESS
    start = read(ct.PRESENT_POSITION)
    assert ph.write4ByteTxRx(port, 2, ct.GOAL_POSITION.address, start + 300)[0] == 0
    clock.sleep(0.1)
    assert (read(ct.MOVING), read(ct.MOVING_STATUS) & 0x02) == (1, 0x02)  # a profile
    emu.inject_hardware_error(2, ct.HardwareFault.OVERLOAD)  # shut down: limp, it falls
    clock.sleep(0.5)
    before = read(ct.PRESENT_POSITION)
    assert 0 < -read(ct.PRESENT_VELOCITY) <= read(ct.MOVING_THRESHOLD)  # falling, slowly
    assert (read(ct.MOVING), read(ct.MOVING_STATUS) & 0x02) == (0, 0)
    clock.sleep(0.5)
    assert read(ct.PRESENT_POSITION) < before  # it does move
    # Moving Threshold is EEPROM, writable with the torque off
    assert ph.write4ByteTxRx(port, 2, ct.MOVING_THRESHOLD.address, 2)[0] == sdk.COMM_SUCCESS
    assert (read(ct.MOVING), read(ct.MOVING_STATUS) & 0x02) == (1, 0)  # fast enough, no profile


def test_real_time_replies_wait_each_servos_return_delay_time_and_wire_time() -> None:
    """A plain ``PortHandler`` on the served pty gets each status packet after its servo's own
    Return Delay Time (9, 2 µs units; factory 250 = 0.5 ms) and the wire time of the packet
    (and of the instruction before it) at the host's baud rate (10 bits a byte): it had
    been a fixed 0.5 ms whatever the register, at no wire speed. Checked as the schedule the
    server sleeps by (no timed test)."""
    from rti_rig.simulator.dynamixel_pty import real_time_replies

    clock = VirtualClock()
    emu = two_servos(clock)
    ping = emu.receive(p2.ping(1))
    assert real_time_replies(emu, ping, 57600) == [(pytest.approx(0.0005 + 140 / 57600), ping)]
    assert real_time_replies(emu, ping, None) == [(pytest.approx(0.0005), ping)]
    # the instruction (a ping is 10 bytes) crosses the wire before the servo can answer it
    assert real_time_replies(emu, ping, 57600, heard=10) == [
        (pytest.approx(0.0005 + 240 / 57600), ping)
    ]
    # servo 2 set to answer at once (a Write of Return Delay Time, torque off)
    assert p2.decode(emu.receive(p2.write(2, ct.RETURN_DELAY_TIME.address, b"\x00"))).error == 0
    both = emu.receive(p2.sync_read(ct.PRESENT_POSITION.address, 4, [1, 2]))
    first, second = both[:15], both[15:]
    assert real_time_replies(emu, both, 1_000_000) == [
        (pytest.approx(0.0005 + 150e-6), first),
        (pytest.approx(150e-6), second),
    ]


def test_a_goal_outside_the_position_limits_is_refused_and_nothing_moves() -> None:
    """e-manual, Min/Max Position Limit: Goal Position "must be within the configured position
    limit range"; an XL430 given one outside does nothing at all, it does not go to the limit
    (ROBOTIS forum, "Position limit in joint mode"). The emulator refuses it with a Data Limit
    Error, keeps the goal it had and stays put; a goal on the limit is taken."""
    clock = VirtualClock()
    servo = EmulatedServo(1, 1060, clock, min_position=1000, max_position=3000)
    emu = DynamixelBusEmulator([servo], clock)
    port = InProcessPort(emu)
    assert port.openPort() and port.setBaudRate(57600)
    ph = sdk.PacketHandler(2.0)
    assert ph.write1ByteTxRx(port, 1, ct.TORQUE_ENABLE.address, 1) == (sdk.COMM_SUCCESS, 0)
    result, error = ph.write4ByteTxRx(port, 1, ct.GOAL_POSITION.address, 3001)
    assert (result, error) == (sdk.COMM_SUCCESS, p2.ERR_DATA_LIMIT)
    clock.sleep(5.0)
    assert ph.read4ByteTxRx(port, 1, ct.GOAL_POSITION.address)[0] == 2048
    assert ph.read4ByteTxRx(port, 1, ct.PRESENT_POSITION.address)[0] == 2048
    assert ph.write4ByteTxRx(port, 1, ct.GOAL_POSITION.address, 3000) == (sdk.COMM_SUCCESS, 0)
    clock.sleep(30.0)
    assert ph.read4ByteTxRx(port, 1, ct.PRESENT_POSITION.address)[0] == 3000
