"""The arm emulator's manual tool serves servos a real arm's check accepts.

``python -m rti_rig.simulator.dynamixel_emulator`` served two XL430s at 2048 ticks each. On the
shipped arm's geometry (elevation zero at 1024 ticks) that is 90° elevation, inside the 15°
keep-out cone, so ``rti-rig check`` on a copy of ``simulated_arm.toml`` pointed at its port was
refused at once: "the arm is not in a safe pose (elevation position 2048 ticks = 90.000 deg
enters the keep-out cone (max 75.000 deg)); move it by hand" — which no one can do to an
emulator. It now serves a rig config's servos at that config's park pose.
"""

from __future__ import annotations

import subprocess
import sys

import pytest
from conftest import CONFIGS

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.kinematics import ArmKinematics
from rti_rig.simulator.dynamixel_emulator import arm_settings_of, served_arm

pytestmark = pytest.mark.pty


def test_the_default_servos_connect_to_the_shipped_arm_outside_its_keep_out() -> None:
    settings, where = arm_settings_of(None)
    assert where.endswith("simulated_arm.toml")
    clock = VirtualClock()
    with served_arm(settings, clock) as (server, emulator):
        pos = emulator.joint_positions()
        kin = ArmKinematics(settings)
        az, el = pos[settings.azimuth.servo_id], pos[settings.elevation.servo_id]
        assert kin.ticks_reason(az, el, "position") is None
        arm = DynamixelArm(settings, server.port_handler(), clock)
        arm.connect()  # refused with SafetyViolation at 2048/2048 ticks
        arm.close()


def test_a_config_other_than_the_shipped_one_is_served_at_its_own_park() -> None:
    settings, _ = arm_settings_of(str(CONFIGS / "simulated_arm.toml"))
    moved = settings.model_copy(update={"park_azimuth_deg": 30.0, "park_elevation_deg": 40.0})
    with served_arm(moved, VirtualClock()) as (_, emulator):
        pos = emulator.joint_positions()
        assert (pos[1], pos[2]) == ArmKinematics(moved).ticks_of_pose(30.0, 40.0)


def test_a_file_without_an_arm_is_named() -> None:
    with pytest.raises(ValueError, match=r"emulated_minirti\.toml: no \[arm\.dynamixel\] table"):
        arm_settings_of(str(CONFIGS / "emulated_minirti.toml"))


def test_the_tool_says_where_the_servos_rest_and_what_to_set() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "rti_rig.simulator.dynamixel_emulator", "--seconds", "0"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "resting at the park pose of" in out.stdout and "elevation 10°" in out.stdout
    assert 'backend = "hardware", [arm.dynamixel] port = "' in out.stdout
