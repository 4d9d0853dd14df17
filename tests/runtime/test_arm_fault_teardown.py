"""A session whose arm faults is not parked by its teardown (the park drove the healthy joint).

Emulated XL430s through the real driver and SDK (in-process port, no real-time thread): the
elevation servo reports an overload in the middle of a move, as a blocked arm would; the
teardown must switch the lamp off and stop, and must then leave the arm where it stopped — no
park goal may reach the bus after the fault. A session that fails for another reason (the
camera) still parks, as ``park_after_session`` says.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO, write_config

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import CaptureError
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.faults import HardwareFaultError
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import run_session
from rti_rig.runtime.session import SessionFolder


def emulated_arm_rig(tmp_path: Path):  # type: ignore[no-untyped-def]
    text = (REPO / "rig_configs" / "simulated_arm.toml").read_text()
    text = text.replace("width = 256", "width = 32").replace("height = 256", "height = 32")
    text = text.replace('transport = "pty"', 'transport = "inprocess"')
    return build_rig(load_rig_config(write_config(tmp_path, text)))


def overload_mid_move(rig, at_move: int) -> list[int]:  # type: ignore[no-untyped-def]
    """Make the elevation servo overload during move ``at_move`` (1-based), once it is under
    way; returns a list that gets the goal log's length at the fault."""
    carrier, emulator = rig.lighting.carrier, rig.emulator
    elevation = emulator.servos[rig.loaded.config.arm.dynamixel.elevation.servo_id]
    moves, reads, mark = [0], [0], []
    real_move, real_read = carrier.move_to, elevation.read

    def move_to(direction: np.ndarray) -> np.ndarray:
        moves[0] += 1
        reads[0] = 0
        return real_move(direction)

    def read(address: int, length: int):  # type: ignore[no-untyped-def]
        if moves[0] == at_move and address == ct.STATUS_BLOCK_START and not mark:
            reads[0] += 1
            if reads[0] == 2:  # the move is under way: the driver has polled it once
                assert elevation.is_moving()
                elevation.inject_hardware_error(ct.HardwareFault.OVERLOAD)
                mark.append(len(emulator.goal_log))
        return real_read(address, length)

    carrier.move_to = move_to
    elevation.read = read
    return mark


def test_an_arm_fault_mid_move_is_not_followed_by_a_park(tmp_path: Path) -> None:
    rig = emulated_arm_rig(tmp_path)
    mark = overload_mid_move(rig, at_move=3)
    out = tmp_path / "s"
    with rig, pytest.raises(HardwareFaultError, match="overload"):
        run_session(rig, plan_uniform(rig.geometry, 8), SessionFolder.create(out, 8))
    assert mark, "the fault was not injected"
    arm, emulator = rig.lighting.carrier, rig.emulator  # type: ignore[attr-defined]
    park = dict(zip(arm.settings.servo_ids, arm.kin.ticks_of_pose(0.0, 10.0), strict=True))
    after = emulator.goal_log[mark[0] :]
    assert not [g for g in after if park[g[0]] == g[1]], f"park goals sent after the fault: {after}"
    assert not arm.lamp_is_on
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    # why it was not parked is where the arm was left, not a teardown failure besides it
    end = runner["arm_end"]
    assert end["outcome"] == "park-unconfirmed"
    assert "not attempted" in end["why"] and "own move failed" in end["why"]
    assert not [f for f in runner["teardown_failures"] if f.startswith("park:")]
    # the close's retry of the stop failed alike: pointed to, not a second paragraph of it
    assert any(
        f.startswith("light close: failed with the same error as 'stop' above")
        for f in runner["teardown_failures"]
    )
    assert sum("Hardware Error Status" in f for f in runner["teardown_failures"]) == 1


def test_a_session_failed_by_the_camera_still_parks_the_arm(tmp_path: Path) -> None:
    rig = emulated_arm_rig(tmp_path)
    real_capture, shots = rig.camera.capture, [0]

    def capture(exposure_s: float):  # type: ignore[no-untyped-def]
        shots[0] += 1
        if shots[0] == 3:
            raise CaptureError(rig.camera.name, "card full", "capture")
        return real_capture(exposure_s)

    rig.camera.capture = capture  # type: ignore[method-assign]
    with rig, pytest.raises(CaptureError):
        run_session(rig, plan_uniform(rig.geometry, 8), SessionFolder.create(tmp_path / "s", 8))
    arm, emulator = rig.lighting.carrier, rig.emulator  # type: ignore[attr-defined]
    ticks = tuple(round(v) for v in emulator.joint_positions().values())
    park = arm.kin.ticks_of_pose(0.0, 10.0)
    assert max(abs(a - b) for a, b in zip(ticks, park, strict=True)) <= 2


def test_an_arm_whose_stop_failed_is_not_parked_either(tmp_path: Path) -> None:
    """The session fails on the camera, and the elevation servo has stopped answering: the
    stop cannot hold it, so the park (a move of both joints) is not sent."""
    rig = emulated_arm_rig(tmp_path)
    emulator, real_capture, shots, mark = rig.emulator, rig.camera.capture, [0], []

    def capture(exposure_s: float):  # type: ignore[no-untyped-def]
        shots[0] += 1
        if shots[0] == 3:
            emulator.silent_ids.add(rig.loaded.config.arm.dynamixel.elevation.servo_id)
            mark.append(len(emulator.goal_log))
            raise CaptureError(rig.camera.name, "card full", "capture")
        return real_capture(exposure_s)

    rig.camera.capture = capture  # type: ignore[method-assign]
    out = tmp_path / "s"
    with rig, pytest.raises(CaptureError):
        run_session(rig, plan_uniform(rig.geometry, 8), SessionFolder.create(out, 8))
    arm = rig.lighting.carrier  # type: ignore[attr-defined]
    park = dict(zip(arm.settings.servo_ids, arm.kin.ticks_of_pose(0.0, 10.0), strict=True))
    after = emulator.goal_log[mark[0] :]
    assert not [g for g in after if park[g[0]] == g[1]], f"park goals sent: {after}"
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert not [f for f in runner["teardown_failures"] if f.startswith("park:")]
    said = runner["arm_end"]["why"]  # why it was not parked: said once, where it was left
    assert "not attempted because the arm's stop failed" in said
    # the elevation joint did not answer the stop: it is not said to have stopped
    assert "left where it stopped" not in said and "failed stop above" in said
