"""`rti-rig check` on a real arm whose lamp is not on the servo bus says it flashed nothing.

The check is said to flash the lamp at each pose; with ``lamp = "software"`` (the default) on
a real arm the lamp's switch is outside the servo bus, and a user watching a lamp that never
lit had been told nothing of why."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from rti_rig.app.usecases.check import WithCamera, _lamp_notes


class _Report:
    ok = True

    def lines(self) -> list[str]:
        return ["arm: 8 poses, tolerance 1°", "parked", "RESULT: PASS"]


def _rig(backend: str, lamp: str) -> SimpleNamespace:
    carrier = SimpleNamespace(settings=SimpleNamespace(lamp=lamp))
    return SimpleNamespace(
        lighting=SimpleNamespace(carrier=carrier),
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
