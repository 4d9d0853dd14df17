"""The after-capture hold check measures from the pose the move reached, not from the goal.

A servo holding a lamp settles off its goal under the load (the XL430's Position I Gain is 0
at the factory: its position loop keeps a steady-state error), within the move's
``in_position_tolerance_ticks``, and may creep a tick or two more. Measured from the goal, an
elevation joint that settled 3 ticks short and crept 2 during an exposure was stopped
mid-session as "moved during the capture" (5 > 4 ticks) though its recorded direction was off
by 2 ticks; a real sag is still caught (test_arm_fault_during_capture.py, the driver tests).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import inprocess_arm_config
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.cli import app


def _run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, creep: int) -> tuple[int, str, Path]:
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        servo, real_capture = rig.emulator.servos[2], rig.camera.capture
        start_move = servo._start_move
        # a loaded elevation joint settles 3 ticks short of each goal (inside the tolerance)
        servo._start_move = lambda goal: start_move(goal - 3)

        def capture(exposure_s: float):  # type: ignore[no-untyped-def]
            # and creeps while the shutter is open
            p = servo.position()
            servo._profile = type(servo._profile)(p - creep, p - creep, servo.clock.now(), 1, 1)
            return real_capture(exposure_s)

        rig.camera.capture = capture
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    cfg = inprocess_arm_config(tmp_path)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "4"], terminal_width=400
    )
    return r.exit_code, " ".join(r.output.split()), out


def test_a_joint_settled_off_its_goal_that_creeps_a_little_is_not_stopped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    code, said, out = _run(tmp_path, monkeypatch, creep=2)
    assert code == 0, said
    assert "moved during the capture" not in said
    assert len(list(out.glob("image_*.jpg"))) == 4


def test_a_joint_that_moves_more_than_the_tolerance_from_where_it_was_is_stopped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    code, said, out = _run(tmp_path, monkeypatch, creep=6)
    assert code != 0, said
    assert "the elevation joint moved during the capture" in said, said
    assert not list(out.glob("image_*.jpg"))
