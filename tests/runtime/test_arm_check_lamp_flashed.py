"""The arm check says it flashed a servo LED lamp, only of the flashes the servo answered.

With ``lamp = "servo_led"`` the check writes the lamp's servo LED on and off at each pose, and
had never said so: a user watching the lamp was not told to look for it, nor that the servo had
taken the writes. A lamp no command reaches (``"software"``, the simulated arm) is not said to
have been flashed.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from conftest import inprocess_arm_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import VirtualClock
from rti_rig.core.devices import ReadBackCarrier
from rti_rig.core.errors import DeviceError
from rti_rig.core.rig_geometry import ArmGeometry
from rti_rig.runtime.arm_check import arm_self_test, self_test_poses

ARM = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)
FLASHED = "lamp: flashed at"


def test_check_says_the_servo_led_lamp_was_flashed_at_each_pose(tmp_path: Path) -> None:
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text()
    assert 'lamp = "software"' in text
    cfg.write_text(text.replace('lamp = "software"', 'lamp = "servo_led"\nlamp_servo_id = 2'))
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    assert r.exit_code == 0, r.output
    assert (
        "\nlamp: flashed at each pose on servo 2's LED, on and off each answered by the servo\n"
    ) in r.output, r.output
    assert r.output.count(FLASHED) == 1


def test_check_does_not_say_a_software_lamp_was_flashed(tmp_path: Path) -> None:
    r = CliRunner().invoke(app, ["check", str(inprocess_arm_config(tmp_path))])
    assert r.exit_code == 0, r.output
    assert FLASHED not in r.output, r.output


class _LedArm(ReadBackCarrier):
    """An arm whose lamp is a servo's LED; its lamp-on write fails (unanswered) at pose
    ``fail_at`` (1-based), as a servo in fault refuses it."""

    name = "arm"
    park_pose_deg = (0.0, 45.0)
    ever_connected = commanded = driven = True  # connected in process, as an arm that answers

    def __init__(self, fail_at: int | None) -> None:
        self.fail_at = fail_at
        self.ons = 0
        self.at = None

    def connect(self) -> None:
        pass

    def close(self) -> None:
        pass

    def unreachable_reason(self, direction):  # type: ignore[no-untyped-def]
        return None

    def move_to(self, direction):  # type: ignore[no-untyped-def]
        self.at = direction
        return direction

    def reached_direction(self):  # type: ignore[no-untyped-def]
        return self.at

    def lamp(self, on: bool) -> None:
        if on:
            self.ons += 1
            if self.ons == self.fail_at:
                raise DeviceError(self.name, "servo 2 did not answer 'write LED = 1'")

    def stop(self) -> None:
        pass

    def park(self, cancelled: Callable[[], bool] | None = None) -> None:
        pass

    def resends(self) -> tuple[list[str], str | None]:
        return [], None

    def torque_release_note(self) -> str | None:
        return None

    def torque_at_close(self) -> None:
        return None

    def lamp_servo(self) -> int | None:
        return 2

    def check_held(self) -> None:
        pass

    def listen(self, say: Callable[[str], None] | None) -> None:
        pass


@pytest.mark.parametrize(("fail_at", "said"), [(None, "each pose"), (3, "2 pose(s)"), (1, None)])
def test_only_the_answered_flashes_are_said(fail_at: int | None, said: str | None) -> None:
    report = arm_self_test(_LedArm(fail_at), ARM, VirtualClock())
    lines = [line for line in report.lines() if line.startswith(FLASHED)]
    if said is None:
        assert lines == [], report.lines()
    else:
        assert lines == [
            f"lamp: flashed at {said} on servo 2's LED, on and off each answered by the servo"
        ], report.lines()
    assert report.lamp_flashes == (len(self_test_poses(ARM)) if fail_at is None else fail_at - 1)
