"""What the closing sentence may say of an arm's lamp: only what was done.

With ``lamp = "software"`` (the default) the lamp's switch is outside the servo bus: on a real
arm rti-rig never switches it, and "lamp off and stop were requested" had told the user it
had been. On an emulated or simulated arm the software lamp is the simulation's, and with
``lamp = "servo_led"`` its off is a write to the servo: there the sentence stays.
"""

from __future__ import annotations

from types import SimpleNamespace

from dxl_support import arm_settings

from rti_rig.app.usecases.safe_state import lights_state
from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.runtime.lighting import ArmLighting
from rti_rig.simulator.dynamixel_emulator import InProcessPort, emulator_for_arm


def said_after_a_session(backend: str, **overrides) -> str:  # type: ignore[no-untyped-def]
    settings = arm_settings(**overrides)
    clock = VirtualClock()
    arm = DynamixelArm(settings, InProcessPort(emulator_for_arm(settings, clock)), clock)
    lighting = ArmLighting(arm, config="arm.toml")
    lighting.connect()
    lighting.safe()
    lighting.close()
    rig = SimpleNamespace(
        lighting=lighting, loaded=SimpleNamespace(config=SimpleNamespace(backend=backend))
    )
    return lights_state(rig)


def test_a_real_arm_s_software_lamp_is_not_said_to_be_switched_off() -> None:
    said = said_after_a_session("hardware")
    assert "lamp off" not in said
    assert "stop was requested" in said and "switch it off yourself" in said


def test_a_servo_led_lamp_or_an_emulated_arm_keeps_the_sentence() -> None:
    # the lamp's part stays; where the arm was left follows it (rti_rig.runtime.arm_end)
    assert said_after_a_session("emulated").startswith("lamp off and stop were requested; ")
    led = said_after_a_session("hardware", lamp="servo_led", lamp_servo_id=2)
    assert led.startswith("lamp off and stop were requested; the arm parked")
