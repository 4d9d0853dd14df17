"""Dry runs of the arm through the real Dynamixel SDK against emulated servos."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, write_config
from typer.testing import CliRunner

from rti_rig.app.compose import arm_order_for, build_rig
from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.cli import app
from rti_rig.core.errors import ConfigError, ScheduleError
from rti_rig.core.geometry import angle_between_deg
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import run_session
from rti_rig.runtime.session import SessionFolder
from rti_rig.testing.verify import wrong_light_steps

runner = CliRunner()


def small_arm(tmp_path: Path, transport: str = "pty") -> Path:
    text = (CONFIGS / "simulated_arm.toml").read_text()
    text = text.replace("width = 256", "width = 40").replace("height = 256", "height = 40")
    return write_config(tmp_path, text.replace('transport = "pty"', f'transport = "{transport}"'))


@pytest.mark.slow
@pytest.mark.pty
@pytest.mark.e2e
def test_cli_dry_run_through_the_real_sdk_on_a_pty(tmp_path: Path) -> None:
    cfg = small_arm(tmp_path)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8"])
    assert r.exit_code == 0, r.output
    steps = json.loads((out / "manifest.json").read_text())["steps"]
    assert len(steps) == 8
    for s in steps:  # reached within a few ticks of the plan (0.088° per tick)
        assert float(angle_between_deg(s["planned_direction"], s["actual_direction"])) < 0.5
    assert wrong_light_steps(cfg, out) == []


def test_arm_parks_and_switches_off_after_the_session(tmp_path: Path) -> None:
    loaded = load_rig_config(small_arm(tmp_path, "inprocess"))
    with build_rig(loaded) as rig:
        schedule = plan_uniform(rig.geometry, 5, arm_order=arm_order_for(loaded))
        run_session(rig, schedule, SessionFolder.create(tmp_path / "s", 5))
        from rti_rig.simulator.dynamixel_emulator import lamp_direction

        arm = rig.lighting.carrier  # type: ignore[attr-defined]
        assert not arm.lamp_is_on
        settings = loaded.config.arm.dynamixel  # type: ignore[union-attr]
        where = lamp_direction(rig.emulator, settings)  # type: ignore[attr-defined]
        assert float(angle_between_deg(where, rig.geometry.park_direction)) < 0.5


def test_move_time_order_beats_plan_order(tmp_path: Path) -> None:
    from rti_rig.core.arm_motion import sequence_time_s

    loaded = load_rig_config(small_arm(tmp_path, "inprocess"))
    settings = loaded.config.arm.dynamixel  # type: ignore[union-attr]
    geometry = rig_geometry(loaded)
    ordered = plan_uniform(geometry, 12, arm_order=arm_order_for(loaded)).directions
    rng = np.random.default_rng(0)
    shuffled = ordered[rng.permutation(12)]
    assert sequence_time_s(ordered, settings) < sequence_time_s(shuffled, settings)


def test_keep_out_and_azimuth_limits_refused_before_moving(tmp_path: Path) -> None:
    loaded = load_rig_config(small_arm(tmp_path, "inprocess"))
    with build_rig(loaded) as rig:
        emulator = rig.emulator  # type: ignore[attr-defined]
        before = dict(emulator.joint_positions())
        bad = LightSchedule(
            (LightStep(direction=(0.1, 0.0, 0.995)), LightStep(direction=(-1.0, 0.001, 0.3)))
        )
        with pytest.raises(ScheduleError) as info:
            run_session(rig, bad, SessionFolder.create(tmp_path / "s", 2))
        text = str(info.value)
        assert "step 1" in text and "step 2" in text
        assert emulator.joint_positions() == before


def test_emulated_arm_needs_its_servos(tmp_path: Path) -> None:
    text = small_arm(tmp_path).read_text()
    head, _, _ = text.partition("[arm.dynamixel]")
    rest = text[text.index("[camera]") :]
    with pytest.raises(ConfigError, match=r"add an \[arm.dynamixel\] table"):
        load_rig_config(write_config(tmp_path, head + rest, "nodxl.toml"))
