"""What ``rti-rig check`` says of where it left an arm, as read back after its stop.

A check stopped part-way (SIGTERM, Ctrl-C) had said "lamp off and stop were requested" and
nothing of the arm, though ``run`` says where it left it (``runner.arm_end``); a completed
check had said "parked" of any park that returned, without reading where the arm was; and a
check aborted by a servo fault said "not parked" twice. Each case runs the CLI on a shipped arm
config; a stop is a real signal through the check's handler, raised at a known call.
"""

from __future__ import annotations

import re
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CONFIGS, built_rigs, inprocess_arm_config, pasted, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import angle_between_deg, direction_from_az_el

AT = re.compile(r"left at az (-?[\d.]+)°, el (-?[\d.]+)°")


def _signal_at_move(
    monkeypatch: pytest.MonkeyPatch,
    n: int,
    sig: signal.Signals,
    before: Callable[[], object] | None = None,
) -> None:
    """Has the check's arm self-test raise ``sig`` as the arm begins its ``n``-th move (the
    check's own handler takes it), ``before`` done first (a servo silenced, say)."""
    import rti_rig.app.usecases.check as check_usecase

    real_self_test = check_usecase.arm_self_test
    moves: list[int] = []

    def self_test(carrier: Any, *args: Any, **kwargs: Any) -> Any:
        real_move = carrier.move_to

        def move_to(direction: np.ndarray) -> np.ndarray:
            moves.append(1)
            if len(moves) == n:
                if before is not None:
                    before()
                signal.raise_signal(sig)
            return real_move(direction)

        carrier.move_to = move_to
        return real_self_test(carrier, *args, **kwargs)

    monkeypatch.setattr(check_usecase, "arm_self_test", self_test)


def _truth(rig: Any) -> np.ndarray:
    """Where the lamp really is: the emulated servos' present positions, or the simulation's."""
    emulator = getattr(rig, "emulator", None)
    if emulator is None:
        return np.asarray(rig.lighting.carrier.reached_direction())
    from rti_rig.simulator.dynamixel_emulator import lamp_direction

    return np.asarray(lamp_direction(emulator, rig.loaded.config.arm.dynamixel))


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize("config", ["virtual_arm.toml", "simulated_arm.toml (inprocess)"])
def test_a_check_stopped_by_sigterm_says_where_the_arm_is_left(
    config: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = inprocess_arm_config(tmp_path) if "inprocess" in config else CONFIGS / config
    rigs = built_rigs(monkeypatch)
    _signal_at_move(monkeypatch, 3, signal.SIGTERM)  # the user's, through the check's handler
    r = CliRunner().invoke(app, ["check", str(path)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 143, said
    assert "Traceback" not in said
    assert (
        "Check stopped (SIGTERM): lamp off and stop were requested; the arm was not parked and "
        "is left at az " in said
    ), said
    assert "(read back; the check was stopped (SIGTERM), and a stopped check does not park)" in said
    found = AT.search(said)
    assert found, said
    said_dir = direction_from_az_el(float(found[1]), float(found[2]))
    (rig,) = rigs
    # what was said is where the arm really is (to the sentence's 0.1°), not its park pose
    assert float(angle_between_deg(said_dir, _truth(rig))) < 0.2, said
    park = direction_from_az_el(*rig.lighting.carrier.park_pose_deg)
    assert float(angle_between_deg(said_dir, park)) > 5.0


def test_a_stopped_check_whose_stop_failed_is_not_said_left_where_it_stopped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGTERM as the azimuth servo stops answering: the teardown's stop cannot hold that
    joint, which may still be moving to its last goal. The arm's sentence had said "left where
    it stopped" beside "the stop did not hold every joint"."""
    rigs = built_rigs(monkeypatch)
    _signal_at_move(monkeypatch, 3, signal.SIGTERM, lambda: rigs[0].emulator.silent_ids.add(1))
    r = CliRunner().invoke(app, ["check", str(inprocess_arm_config(tmp_path))], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 143, said
    assert "teardown problem: stop:" in said, said
    assert (
        "Check stopped (SIGTERM): lamp off was requested, but the stop failed at a servo (not "
        "sent, or sent and not acknowledged): the azimuth servo (id 1) gives no reply, so "
        "nothing is known of it: unpowered, a servo is limp and the arm turns freely about the "
        "vertical if pushed; powered, it keeps its last goal under torque, and the arm may hold "
        "there or still be moving to it; look at the arm before touching it, switch the arm's "
        "power supply off; the arm was not parked (the "
        "check was stopped (SIGTERM), and a stopped check does not park; the stop did not hold "
        "every joint (see the teardown above): its position is not read as where it is left)"
        in said
    ), said
    assert "left where it stopped" not in said and "left at az" not in said, said
    # the park command, once the arm is made safe: not "To park it" of an arm that may be moving
    assert "Once the arm is safe (the lines above say how), park it with rti-rig check " in said
    assert "To park it" not in said, said


def test_a_park_that_returns_off_its_pose_is_not_said_parked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The emulated arm's park returns without moving (as a goal the servos ignored would): the
    check had said "parked" and PASS of an arm it had left at its last pose."""
    rigs = built_rigs(monkeypatch)
    import rti_rig.app.usecases.check as check_usecase

    real_self_test = check_usecase.arm_self_test

    def self_test(carrier: Any, *args: Any, **kwargs: Any) -> Any:
        carrier.park = lambda: None
        return real_self_test(carrier, *args, **kwargs)

    monkeypatch.setattr(check_usecase, "arm_self_test", self_test)
    r = CliRunner().invoke(app, ["check", str(inprocess_arm_config(tmp_path))], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "park NOT confirmed: read back " in said and "from the park pose (az 0°, el 10°)" in said
    assert not re.search(r"(^| )parked", said), said
    found = AT.search(said)
    assert found, said
    said_dir = direction_from_az_el(float(found[1]), float(found[2]))
    assert float(angle_between_deg(said_dir, _truth(rigs[0]))) < 0.2, said


def test_a_check_aborted_by_an_overload_says_not_parked_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Servo 2 overloads (its torque off, so the stop cannot hold it): the abort line had said
    "not parked; the stop did not hold every joint" and the park line "NOT parked" again."""
    cfg = inprocess_arm_config(tmp_path, servo_fault(60, 2))
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    assert said.lower().count("not parked") == 1, said
    assert said.count("the stop did not hold every joint") == 1, said
    assert (
        "NOT parked: not attempted after the error above; the stop did not hold every joint "
        "(see the teardown above): its position is not read as where it is left" in said
    ), said


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_check_stopped_by_ctrl_c_says_the_poses_it_verified_and_how_to_park(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C as the arm moves to its 4th pose: the three poses it had reached and measured
    are listed, the 4th as cut short (not a failure), where the arm was left (read back), and
    the command that parks it, pasteable (a config in a folder with a space). A stopped check
    had printed none of its verified poses and no way to park the arm."""
    folder = tmp_path / "my rigs"
    folder.mkdir()
    cfg = folder / "arm.toml"
    cfg.write_text(inprocess_arm_config(tmp_path).read_text())
    rigs = built_rigs(monkeypatch)
    _signal_at_move(monkeypatch, 4, signal.SIGINT)  # the user's Ctrl-C, through its handler
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 130 and "Traceback" not in said, said
    assert "arm: stopped (Ctrl-C) at pose 4 of 8; 3 verified within 1°" in said, said
    rows = re.findall(r"(low|high|middle), az -?\d+° .*? (ok|not verified)", r.output)
    assert [verdict for _, verdict in rows] == ["ok", "ok", "ok", "not verified"], r.output
    assert "not verified: stopped (Ctrl-C) during this move" in said, said
    assert "RESULT" not in said and "ABORTED" not in said, said
    found = AT.search(said)
    assert found and "(read back; the check was stopped (Ctrl-C)" in said, said
    (rig,) = rigs
    at = direction_from_az_el(float(found[1]), float(found[2]))
    assert float(angle_between_deg(at, _truth(rig))) < 0.2, said
    hint = re.search(
        r"To park it: rti-rig check (.+?) --park-only \(it moves to the park pose, nothing else\)",
        said,
    )
    assert hint is not None, said
    assert pasted(hint[1].encode()) == str(cfg).encode(), said
