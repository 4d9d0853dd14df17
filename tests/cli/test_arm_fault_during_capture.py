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
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct


def test_a_servo_that_overloads_during_an_exposure_loses_that_image_not_its_direction(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        emu, real_capture = rig.emulator, rig.camera.capture
        shots = []

        def capture(exposure_s: float):  # type: ignore[no-untyped-def]
            frame = real_capture(exposure_s)
            shots.append(exposure_s)
            if len(shots) == 3:  # the elevation servo overloads while image 3 exposes
                emu.inject_hardware_error(2, ct.HardwareFault.OVERLOAD)
            return frame

        rig.camera.capture = capture
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    text = (CONFIGS / "simulated_arm.toml").read_text()
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text.replace('transport = "pty"', 'transport = "inprocess"'))
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
