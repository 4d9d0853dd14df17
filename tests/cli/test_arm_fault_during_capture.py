"""An image whose exposure a servo fault overlapped is not kept under the direction read before.

A real X-series servo that overloads switches its torque off (ROBOTIS e-manual, Shutdown (63))
and the arm sags. One that overloaded while the shutter was open had its image kept and listed
in lights.lp under the direction read before the capture; the fault was found only at the next
move. The arm is now read after each capture: the fault stops the run there, the image is not
kept, and a resume retakes the step.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import inprocess_arm_config
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct


def test_a_servo_that_overloads_during_an_exposure_loses_that_image_not_its_direction(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_build = compose.build_rig
    emulators: list = []  # type: ignore[type-arg]
    held: list[float] = []

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        emu, real_capture = rig.emulator, rig.camera.capture
        emulators.append(emu)
        shots = []

        def capture(exposure_s: float):  # type: ignore[no-untyped-def]
            shots.append(exposure_s)
            if len(shots) == 3:  # the elevation servo overloads as image 3 starts exposing
                emu.inject_hardware_error(2, ct.HardwareFault.OVERLOAD)
                held.append(emu.servos[2].position())
            return real_capture(exposure_s)

        rig.camera.capture = capture
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    cfg = inprocess_arm_config(tmp_path)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "6"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code != 0, said
    assert "servo 2: hardware fault overload" in said, said
    assert "2 image(s) kept" in said, said
    assert sorted(p.name for p in out.glob("image_*.jpg")) == ["image_001.jpg", "image_002.jpg"]
    steps = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    assert len(steps) == 2
    # the truth: the shut-down elevation servo is limp and its loaded joint has fallen from
    # the goal it held for image 3 towards its lower stop (the emulated arm had frozen there)
    (emu,) = emulators
    servo = emu.servos[2]
    assert servo.get(ct.TORQUE_ENABLE) == 0
    assert servo.position() < held[0] - 4, (servo.position(), held)
