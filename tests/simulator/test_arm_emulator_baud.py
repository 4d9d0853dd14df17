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
