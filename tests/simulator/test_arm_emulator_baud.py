"""The manual arm emulator serves its servos at the baud rate they are set to, and only at it.

Real servos ship at several rates (X series 57600; many users raise it to 1 Mbps), and a servo
at another rate than the host's answers nothing (ROBOTIS e-manual, Baud Rate (8)). The tool
had always served 57600, so a bus set to 1 Mbps could not be rehearsed; ``--baud`` (and
``served_arm``'s ``baudrate``) now sets the servos' Baud Rate register.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel.bus import DxlBus
from rti_rig.drivers.dynamixel.faults import CommunicationError
from rti_rig.simulator.dynamixel_emulator import arm_settings_of, served_arm

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="pty line speed, tested on Linux"),
]


def test_servos_set_to_1_mbps_answer_at_it_and_not_at_the_factory_rate() -> None:
    settings, _ = arm_settings_of(None)
    with served_arm(settings, VirtualClock(), 1_000_000) as (server, _emulator):
        bus = DxlBus(server.port_handler(), "arm on A")
        bus.open(57600)
        try:
            with pytest.raises(CommunicationError):
                bus.ping(1)
        finally:
            bus.close()
        bus = DxlBus(server.port_handler(), "arm on A")
        bus.open(1_000_000)
        try:
            assert bus.ping(1) == 1060
        finally:
            bus.close()


def test_the_tool_says_the_rate_it_serves_and_refuses_one_no_servo_runs_at() -> None:
    run = [sys.executable, "-m", "rti_rig.simulator.dynamixel_emulator", "--seconds", "0"]
    out = subprocess.run([*run, "--baud", "1000000"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "at 1000000 baud" in out.stdout
    assert "baudrate = 57600, but these servos talk at 1000000" in out.stdout
    bad = subprocess.run([*run, "--baud", "38400"], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "--baud 38400" in bad.stderr


def test_the_tool_raises_a_servos_hardware_error_as_emulator_faults_does() -> None:
    """``--fault K:KIND[:ID]``, as ``[[emulator.faults]]``: the dome firmware tool took one and
    this one did not, so an overload could not be rehearsed on the served pty."""
    from rti_rig.drivers.dynamixel import control_table as ct
    from rti_rig.simulator.dynamixel_emulator import parse_tool_fault

    settings, _ = arm_settings_of(None)
    fault = parse_tool_fault("2:overload:2", (1, 2))
    assert fault == (2, "overload", 2, 1.0)
    with served_arm(settings, VirtualClock(), 57600, [fault]) as (server, emulator):
        bus = DxlBus(server.port_handler(), "arm on A")
        bus.open(57600)
        try:
            assert bus.ping(2) == 1060  # packet 1: all well
            bus.ping(1)  # packet 2: servo 2 overloads as it arrives
            status = bus.read(2, ct.HARDWARE_ERROR_STATUS, check_alert=False)
        finally:
            bus.close()
    assert status & ct.HardwareFault.OVERLOAD
    assert emulator.servos[2].get(ct.TORQUE_ENABLE) == 0  # the XL430 shuts down for it
    run = [sys.executable, "-m", "rti_rig.simulator.dynamixel_emulator", "--seconds", "0"]
    out = subprocess.run(
        [
            *run,
            "--fault",
            "60:overload:2",
            "--fault",
            "3:drop_reply",
            "--fault",
            "4:delay_reply:0.25",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "Fault: servo 2's overload at instruction packet 60" in out.stdout
    assert "Fault: delay_reply (its status 0.25 s late) at instruction packet 4" in out.stdout
    bad = subprocess.run(
        [*run, "--fault", "60:overload"], capture_output=True, text=True, timeout=120
    )
    assert bad.returncode == 2 and "needs the servo's id" in bad.stderr


def test_the_manual_tool_rehearses_a_late_status_with_its_delay() -> None:
    """``--fault K:delay_reply[:SECONDS]``, as ``[[emulator.faults]]`` ``delay_s``: a slow
    adapter's late status could be rehearsed in a rig config but the tool refused it."""
    from rti_rig.simulator.dynamixel_emulator import parse_tool_fault

    assert parse_tool_fault("4:delay_reply:0.25", (1, 2)) == (4, "delay_reply", None, 0.25)
    assert parse_tool_fault("4:delay_reply", (1, 2)).delay_s == 1.0  # as delay_s's default
    for bad in ("4:delay_reply:61", "4:delay_reply:-1", "4:delay_reply:soon", "4:drop_reply:2"):
        with pytest.raises(ValueError, match="K:delay_reply:SECONDS"):
            parse_tool_fault(bad, (1, 2))
    settings, _ = arm_settings_of(None)
    late = parse_tool_fault("3:delay_reply:0.25", (1, 2))
    with served_arm(settings, VirtualClock(), 57600, [late]) as (_server, emulator):
        assert emulator.reply_faults[3] == "delay_reply"
        assert emulator.reply_delays[3] == 0.25
