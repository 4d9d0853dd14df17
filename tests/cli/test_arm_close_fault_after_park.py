"""A servo that faults after the final park was read back: the run takes "parked" back.

The emulated arm's elevation servo, overloaded at the close's read after the park (its torque
off, the joint limp: the arm fell from the park pose), was said and recorded as "the arm parked
(read back at az 0.0°, el 10.0°, within 1° of its park pose)", beside the teardown problem
naming the fault; the manifest's ``runner.arm_end`` kept ``"parked"``; and the closing advice
told the arm's user to "switch the dome or lamp off", with no word of the limp joint. Through
the CLI on the shipped emulated arm, the fault raised in its emulator as the arm's close
begins (not at a packet count, which any change to the driver's traffic would move).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.app import compose
from rti_rig.cli import app
from rti_rig.runtime.lighting import ArmLighting

#: Hardware Error Status bit of an overload (ROBOTIS e-manual, X series, address 70).
OVERLOAD = 0x20


def test_a_fault_after_the_park_is_no_parked_arm(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("RTI_RIG_EMULATOR_STATE_DIR", str(tmp_path / "emulator"))
    built: list[Any] = []
    real_build, real_close = compose.build_rig, ArmLighting.close

    def build_rig(*args: Any, **kwargs: Any) -> Any:
        built.append(real_build(*args, **kwargs))
        return built[-1]

    def close(self: ArmLighting) -> None:
        assert self.end is not None and self.end.outcome == "parked"  # read back at the park
        built[-1].emulator.inject_hardware_error(2, OVERLOAD)  # the elevation servo
        real_close(self)

    monkeypatch.setattr(compose, "build_rig", build_rig)
    monkeypatch.setattr(ArmLighting, "close", close)
    cfg = tmp_path / "arm.toml"
    cfg.write_text((CONFIGS / "simulated_arm.toml").read_text())
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", "4", "--no-verdict"]
    r = CliRunner().invoke(app, args, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said  # complete, not safe
    assert "teardown problem: light close" in said and "overload" in said, said
    assert "the arm parked" not in said, said
    assert "the arm's park is NOT confirmed: its close failed after the park was read" in said
    assert "support the arm, a joint of which may be limp" in said, said
    assert f"rti-rig check {cfg} --park-only parks it" in said, said
    assert "switch the dome" not in said, said
    end = json.loads((out / "manifest.json").read_text())["runner"]["arm_end"]
    assert end["outcome"] == "park-unconfirmed", end
    assert "its close failed after the park was read back" in end["why"], end
