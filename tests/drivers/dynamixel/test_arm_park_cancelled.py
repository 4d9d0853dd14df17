"""A park cancelled part-way holds the arm where it stands (goal = present, torque on).

Why: the teardown's park could not be stopped: a user's Ctrl-C sat out the whole move. The
driver's park now asks ``cancelled`` before each poll of its wait; the hold it then writes is
checked on the emulated servos (a torque-off would drop the lamp onto the object).
"""

from __future__ import annotations

import pytest
from dxl_support import arm_settings

from rti_rig.core.clock import VirtualClock
from rti_rig.core.errors import MoveCancelled
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.simulator.dynamixel_emulator import InProcessPort, emulator_for_arm


def test_a_park_cancelled_part_way_holds_the_arm_where_it_stands() -> None:
    settings = arm_settings()
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    arm = DynamixelArm(settings, InProcessPort(emu), clock)
    arm.connect()
    arm.move_to(direction_from_az_el(60, 70))
    polls: list[int] = []

    def cancelled() -> bool:  # asked once a poll: the third time, part-way through the park
        polls.append(1)
        return len(polls) >= 3

    with pytest.raises(MoveCancelled, match="held where it stopped"):
        arm.park(cancelled=cancelled)
    park = arm.kin.ticks_of_pose(0.0, 10.0)
    clock.sleep(5.0)  # long enough for any move to end: the arm stays where it was held
    present = tuple(round(v) for v in emu.joint_positions().values())
    goals = tuple(emu.servos[j.servo_id].get(ct.GOAL_POSITION) for j in settings.joints)
    assert all(abs(p - g) <= 4 for p, g in zip(present, goals, strict=True)), (present, goals)
    assert abs(present[1] - park[1]) > 100  # stopped short of the park pose
    assert [emu.servos[j.servo_id].get(ct.TORQUE_ENABLE) for j in settings.joints] == [1, 1]
    arm.park()  # not cancelled: parks as ever
    assert all(
        abs(round(p) - g) <= 4 for p, g in zip(emu.joint_positions().values(), park, strict=True)
    )
    arm.close()
