"""``rti-rig check RIG --park-only``: park the arm and move nothing else.

A check or run that left the arm mid-pose advised "park it with rti-rig check RIG", which
walks all eight self-test poses again before it parks. Each case runs the CLI on the shipped
emulated arm (servos in-process; their powered state kept between commands as on a chain that
stays powered), a stop being a real signal through the command's handler.
"""

from __future__ import annotations

import re
import shlex
import signal
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import CONFIGS, built_rigs, inprocess_arm_config
from typer.testing import CliRunner

from rti_rig.cli import app


def _invoke(*argv: str) -> tuple[int, str]:
    r = CliRunner().invoke(app, list(argv), terminal_width=400)
    return r.exit_code, " ".join(r.output.split())


def _ctrl_c_at_move(monkeypatch: pytest.MonkeyPatch, n: int) -> None:
    """Has the check's arm self-test raise SIGINT as the arm begins its ``n``-th move (the
    check's own handler takes it): the arm is left there, away from the park pose."""
    import rti_rig.app.usecases.check as check_usecase

    real_self_test = check_usecase.arm_self_test

    def self_test(carrier: Any, *args: Any, **kwargs: Any) -> Any:
        moves: list[int] = []
        real_move = carrier.move_to

        def move_to(direction: np.ndarray) -> np.ndarray:
            moves.append(1)
            if len(moves) == n:
                signal.raise_signal(signal.SIGINT)
            return real_move(direction)

        carrier.move_to = move_to
        return real_self_test(carrier, *args, **kwargs)

    monkeypatch.setattr(check_usecase, "arm_self_test", self_test)


def _park_ticks(rig: Any) -> tuple[int, ...]:
    s = rig.lighting.carrier.settings
    return tuple(
        int(t)
        for t in rig.lighting.carrier.kin.ticks_of_pose(s.park_azimuth_deg, s.park_elevation_deg)
    )


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_the_park_a_stopped_check_advises_parks_and_moves_nothing_else(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Ctrl-C at the check's 4th pose; the advised command, pasted, parks the arm: its only
    goals are the connect's (where it stands) and the park pose (the check it had advised
    walked eight poses first)."""
    folder = tmp_path / "my rigs"
    folder.mkdir()
    cfg = folder / "arm.toml"
    cfg.write_text(inprocess_arm_config(tmp_path).read_text())
    rigs = built_rigs(monkeypatch)
    _ctrl_c_at_move(monkeypatch, 4)
    code, said = _invoke("check", str(cfg))
    assert code == 130, said
    hint = re.search(r"To park it: (rti-rig check .+? --park-only) \(", said)
    assert hint is not None, said
    argv = shlex.split(hint[1])[1:]
    assert argv == ["check", str(cfg), "--park-only"], argv
    code, said = _invoke(*argv)
    assert code == 0 and "Traceback" not in said, said
    assert "the arm parked (read back at az 0.0°, el 10.0°" in said and "RESULT: PASS" in said
    assert "pose" not in said.replace("park pose", ""), said  # no walk
    rig = rigs[-1]
    park = _park_ticks(rig)
    goals = {dxl_id: {g for i, g in rig.emulator.goal_log if i == dxl_id} for dxl_id in (1, 2)}
    # the connect's goal (where the arm stood) and the park's: no other pose was visited
    assert all(len(g) <= 2 for g in goals.values()), goals
    assert [rig.emulator.goal_log[-2][1], rig.emulator.goal_log[-1][1]] == list(park)


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize(
    ("sig", "code", "who"), [(signal.SIGINT, 130, "Ctrl-C"), (signal.SIGTERM, 143, "SIGTERM")]
)
def test_a_stop_during_the_park_holds_the_arm_and_says_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, sig: signal.Signals, code: int, who: str
) -> None:
    """A stop as the park begins: the arm is held where it stands, torque on, said "not
    parked" with where it was read back, and the park command given again."""
    from rti_rig.drivers.dynamixel import control_table as ct
    from rti_rig.drivers.dynamixel.arm import DynamixelArm

    cfg = inprocess_arm_config(tmp_path)
    with monkeypatch.context() as stopped_check:  # the arm left away from its park pose
        _ctrl_c_at_move(stopped_check, 4)
        assert _invoke("check", str(cfg))[0] == 130
    rigs = built_rigs(monkeypatch)
    real_park = DynamixelArm.park

    def park(self: Any, *args: Any, **kwargs: Any) -> Any:
        signal.raise_signal(sig)  # held by the teardown; the park's wait sees it
        return real_park(self, *args, **kwargs)

    monkeypatch.setattr(DynamixelArm, "park", park)
    got, said = _invoke("check", str(cfg), "--park-only")
    assert got == code and "Traceback" not in said, said
    assert f"Park stopped ({who}):" in said, said
    assert f"the park was stopped by {who}: held where it stopped, torque on" in said, said
    assert "the arm parked" not in said and "RESULT" not in said, said
    (rig,) = rigs
    servos = [rig.emulator.servos[j.servo_id] for j in rig.lighting.carrier.settings.joints]
    assert [s.get(ct.TORQUE_ENABLE) for s in servos] == [1, 1]  # "hold": torque kept on
    end = rig.lighting.end
    assert end is not None and end.outcome == "left", end
    assert end.elevation_deg is not None and abs(end.elevation_deg - 10.0) > 5.0, end
    assert f"To park it: rti-rig check {cfg} --park-only." in said, said


def test_a_fault_during_the_park_is_not_called_parked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A servo that overloads as the park begins: the park is said NOT confirmed, with the
    servo's fault, exit 1, no traceback."""
    from rti_rig.drivers.dynamixel.arm import DynamixelArm
    from rti_rig.simulator.dynamixel_emulator import HARDWARE_FAULT_BITS

    cfg = inprocess_arm_config(tmp_path)
    rigs = built_rigs(monkeypatch)
    real_park = DynamixelArm.park

    def park(self: Any, *args: Any, **kwargs: Any) -> Any:
        rigs[-1].emulator.inject_hardware_error(2, int(HARDWARE_FAULT_BITS["overload"]))
        return real_park(self, *args, **kwargs)

    monkeypatch.setattr(DynamixelArm, "park", park)
    code, said = _invoke("check", str(cfg), "--park-only")
    assert code == 1 and "Traceback" not in said, said
    assert "the arm's park is NOT confirmed: the park failed" in said, said
    assert "verload" in said and "RESULT: FAIL" in said, said


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (
            ["check", str(CONFIGS / "simulated_dome.toml"), "--park-only"],
            "--park-only parks an arm; this rig config describes a dome, which has no park pose",
        ),
        (  # an .lp replayed, no rig config and no LED: said as what it is
            ["check", "{acq}", "--park-only"],
            "{acq}: --park-only parks an arm; this is a replayed acquisition (a .lp and its "
            "images), with nothing to move. To check it: rti-rig check {acq}",
        ),
        (
            ["check", str(CONFIGS / "simulated_arm.toml"), "--park-only", "--reboot-faulted"],
            "--park-only parks the arm and does nothing else: drop --reboot-faulted",
        ),
        (  # both problems in one refusal, the dome's check keeping the level asked for
            ["check", str(CONFIGS / "simulated_dome.toml"), "--park-only", "--intensity", "0.5"],
            "has no park pose. To check it (its check ends with every LED switched off): "
            f"rti-rig check {CONFIGS / 'simulated_dome.toml'} --intensity 0.5",
        ),
        (
            ["check", "{acq}", "--park-only", "--intensity", "0.5", "--reboot-faulted"],
            "with nothing to move. To check it (--reboot-faulted and --intensity left out, "
            "which a replay's check does not take): rti-rig check {acq}",
        ),
    ],
    ids=["dome", "replay", "with-reboot", "dome-with-intensity", "replay-with-options"],
)
def test_park_only_refused_where_there_is_nothing_to_park(
    argv: list[str], words: str, tmp_path: Path
) -> None:
    import cv2

    acq = tmp_path / "dirs.lp"  # a replay: its .lp and the one image it lists
    acq.write_text("1\nimg.jpg 0 0 1\n")
    cv2.imwrite(str(tmp_path / "img.jpg"), np.zeros((8, 8, 3), np.uint8))
    code, said = _invoke(*(a.replace("{acq}", str(acq)) for a in argv))
    words = words.replace("{acq}", str(acq))
    assert code == 2 and words in said and "Parking" not in said, said


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_stopped_park_at_the_park_pose_is_released_by_release_on_close(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/protocols/dynamixel-arm.md's word on a stopped ``--park-only``: held where it
    stands, torque on, *unless* ``torque_policy = "release_on_close"`` and the arm is at its
    park pose, which the close then releases (the doc had said it holds, whatever the
    policy). The arm parked and held first; a Ctrl-C as the second park begins; the servos' Torque
    Enable read from the emulator, the truth."""
    from rti_rig.drivers.dynamixel import control_table as ct
    from rti_rig.drivers.dynamixel.arm import DynamixelArm

    cfg = inprocess_arm_config(tmp_path)
    assert _invoke("check", str(cfg), "--park-only")[0] == 0  # parked, held ("hold")
    text = cfg.read_text()
    assert 'torque_policy = "hold"' in text
    cfg.write_text(text.replace('torque_policy = "hold"', 'torque_policy = "release_on_close"'))
    rigs = built_rigs(monkeypatch)
    real_park = DynamixelArm.park

    def park(self: Any, *args: Any, **kwargs: Any) -> Any:
        signal.raise_signal(signal.SIGINT)  # held by the teardown; the park's wait sees it
        return real_park(self, *args, **kwargs)

    monkeypatch.setattr(DynamixelArm, "park", park)
    got, said = _invoke("check", str(cfg), "--park-only")
    assert got == 130 and "Traceback" not in said, said
    assert "close enough to the park pose for the close to release it" in said, said
    assert "torque on" not in said, said
    (rig,) = rigs
    servos = [rig.emulator.servos[j.servo_id] for j in rig.lighting.carrier.settings.joints]
    assert [s.get(ct.TORQUE_ENABLE) for s in servos] == [0, 0]  # released, not held
