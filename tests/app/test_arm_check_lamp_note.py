"""`rti-rig check` on a real arm whose lamp is not on the servo bus says it flashed nothing.

The check is said to flash the lamp at each pose; with ``lamp = "software"`` (the default) on
a real arm the lamp's switch is outside the servo bus, and a user watching a lamp that never
lit had been told nothing of why."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from dxl_support import arm_settings

from rti_rig.app.usecases.check import WithCamera, _lamp_notes
from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.runtime.lighting import ArmLighting
from rti_rig.simulator.dynamixel_emulator import InProcessPort, emulator_for_arm


class _Report:
    ok = True

    def lines(self) -> list[str]:
        return ["arm: 8 poses, tolerance 1°", "parked", "RESULT: PASS"]


def _rig(backend: str, lamp: str) -> SimpleNamespace:
    """A rig whose lighting is a Dynamixel arm (on emulated servos) with ``lamp``: the note is
    asked of the arm's declared type, so a bare namespace with a ``settings.lamp`` is none."""
    overrides = {"lamp": lamp, "lamp_servo_id": 2} if lamp == "servo_led" else {"lamp": lamp}
    settings = arm_settings(**overrides)
    clock = VirtualClock()
    arm = DynamixelArm(settings, InProcessPort(emulator_for_arm(settings, clock)), clock)
    return SimpleNamespace(
        lighting=ArmLighting(arm, config="arm.toml"),
        loaded=SimpleNamespace(config=SimpleNamespace(backend=backend)),
    )


def test_a_real_arm_with_a_software_lamp_is_told_no_flash_reached_it() -> None:
    notes = _lamp_notes(_rig("hardware", "software"))
    lines = WithCamera(_Report(), ("camera: uvc connected (no image taken)", True), notes).lines()
    assert lines[-1] == "RESULT: PASS"
    lamp = next(line for line in lines if line.startswith("lamp: "))
    assert 'not switched by rti-rig (lamp = "software" in [arm.dynamixel]' in lamp
    assert "no flash reached it" in lamp and 'lamp = "servo_led"' in lamp
    assert lines.index(lamp) < lines.index("camera: uvc connected (no image taken)")


@pytest.mark.parametrize(("backend", "lamp"), [("hardware", "servo_led"), ("emulated", "software")])
def test_a_lamp_the_rig_switches_or_simulates_needs_no_note(backend: str, lamp: str) -> None:
    assert _lamp_notes(_rig(backend, lamp)) == ()


def test_a_simulated_arm_needs_no_note(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """The shipped virtual arm's lamp is the simulation's: no note, on any backend."""
    from conftest import CONFIGS

    from rti_rig.app.compose import build_rig
    from rti_rig.app.config import load_rig_config

    rig = build_rig(load_rig_config(CONFIGS / "virtual_arm.toml"))
    assert _lamp_notes(rig) == ()
