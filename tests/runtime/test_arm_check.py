"""Arm self-test (`rti-rig check` on an arm): poses span the band, errors are caught, teardown."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, inprocess_arm_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import VirtualClock
from rti_rig.core.errors import DeviceError
from rti_rig.core.geometry import az_el_from_direction, direction_from_az_el
from rti_rig.core.rig_geometry import ArmGeometry
from rti_rig.runtime.arm_check import arm_self_test, self_test_poses

runner = CliRunner()
ARM = ArmGeometry(5.0, 80.0, 10.0, 0.0, 45.0)


class FakeCarrier:
    """A carrier that records what it was told; optional aim error, failure and refusal."""

    name = "fake arm"

    def __init__(
        self, aim_error_deg: float = 0.0, fail_on_move: int | None = None, refuse: bool = False
    ) -> None:
        self.log: list[str] = []
        self.aim_error_deg = aim_error_deg
        self.fail_on_move = fail_on_move
        self.refuse = refuse
        self.moves = 0
        self.at = direction_from_az_el(*self.park_pose_deg)

    def connect(self) -> None:
        self.log.append("connect")

    def close(self) -> None:
        self.log.append("close")

    def unreachable_reason(self, direction: np.ndarray) -> str | None:
        return "the fake refuses everything" if self.refuse else None

    #: (azimuth, elevation) it parks at: ARM's park pose
    park_pose_deg = (0.0, 45.0)

    def move_to(self, direction: np.ndarray) -> np.ndarray:
        self.moves += 1
        if self.fail_on_move == self.moves:
            raise DeviceError(self.name, "servo 2 reports an overload error")
        self.log.append("move")
        az, el = az_el_from_direction(np.asarray(direction))
        self.at = direction_from_az_el(float(az), float(el) - self.aim_error_deg)
        return self.at

    def reached_direction(self) -> np.ndarray:
        """Where it is (read back): its last move's or its park's direction."""
        return self.at

    def lamp(self, on: bool) -> None:
        self.log.append(f"lamp {'on' if on else 'off'}")

    def stop(self) -> None:
        self.log.append("stop")

    def park(self, cancelled: Callable[[], bool] | None = None) -> None:
        """As the LightCarrier protocol's (``cancelled``: the final park's stop, not asked)."""
        self.log.append("park")
        self.at = direction_from_az_el(*self.park_pose_deg)


class RenamedCarrier(FakeCarrier):
    """The fake carrier under another name."""

    def __init__(self, name: str) -> None:
        super().__init__()
        self.name = name  # type: ignore[misc]


@pytest.mark.parametrize(
    "geometry",
    [ARM, ArmGeometry(0.0, 75.0, 15.0, -170.0, 0.0, -170.0, 170.0)],
    ids=["full turn", "limited azimuth"],
)
def test_poses_span_the_band_inside_every_limit(geometry: ArmGeometry) -> None:
    poses = self_test_poses(geometry)
    dirs = np.array([d for _, d in poses])
    assert all(geometry.unreachable_reason(d) is None for d in dirs)
    az, el = az_el_from_direction(dirs)
    lo, hi = geometry.elevation_band()
    assert el.min() == pytest.approx(lo + 0.5) and el.max() == pytest.approx(hi - 0.5)
    az = np.where(az > 180.0, az - 360.0, az)
    span = az.max() - az.min()
    assert span >= min(180.0, geometry.max_azimuth_deg - geometry.min_azimuth_deg - 1.0) - 1e-6


def test_a_good_arm_passes_flashes_the_lamp_and_parks() -> None:
    carrier = FakeCarrier()
    report = arm_self_test(carrier, ARM, VirtualClock())
    assert report.ok, report.lines()
    assert carrier.log.count("move") == len(self_test_poses(ARM))
    assert carrier.log.count("lamp on") == carrier.log.count("move")
    assert carrier.log[-4:] == ["park", "lamp off", "stop", "close"]
    assert report.lines()[-1] == "RESULT: PASS"


def test_an_arm_that_misses_its_target_fails_naming_the_error() -> None:
    report = arm_self_test(FakeCarrier(aim_error_deg=2.0), ARM, VirtualClock())
    assert not report.ok
    assert all(not c.ok for c in report.checks)
    text = "\n".join(report.lines())
    assert "reached 2.00° from the asked direction" in text
    assert text.endswith("RESULT: FAIL")


def test_a_device_error_aborts_without_parking_but_makes_the_arm_safe() -> None:
    carrier = FakeCarrier(fail_on_move=3)
    report = arm_self_test(carrier, ARM, VirtualClock())
    assert not report.ok
    assert report.aborted and "overload" in report.aborted
    assert "park" not in carrier.log
    assert carrier.log[-3:] == ["lamp off", "stop", "close"]
    assert len(report.checks) == 3 and not report.checks[-1].ok
    # where it was left, read back after the stop: the pose it reached before the failed one
    assert report.end is not None and report.end.outcome == "park-unconfirmed"
    az, el = az_el_from_direction(carrier.at)
    assert report.end.elevation_deg == pytest.approx(float(el))
    text = "\n".join(report.lines())
    assert f"NOT parked: not attempted after the error above; left at az {float(az):.1f}°" in text
    assert "parked (read back" not in text


def test_the_heading_says_how_far_an_aborted_walk_got() -> None:
    """A walk stopped by a device error at pose 3 of 8 had been headed "fake arm: 3 poses", as
    if three were all it was to visit; one whose connect failed, "0 poses" over an empty table."""
    report = arm_self_test(FakeCarrier(fail_on_move=3), ARM, VirtualClock())
    planned = len(self_test_poses(ARM))
    assert report.lines()[0] == f"fake arm: stopped at pose 3 of {planned}, tolerance 1°"

    class NoConnect(FakeCarrier):
        def connect(self) -> None:
            raise DeviceError(self.name, "cannot open port 'COM9'")

    lines = arm_self_test(NoConnect(), ARM, VirtualClock()).lines()
    assert lines[0] == "fake arm: no pose visited (see ABORTED below)", lines
    assert not any("asked az/el" in line for line in lines)  # no empty table


def test_any_other_error_is_reported_too_and_the_arm_made_safe() -> None:
    carrier = FakeCarrier()

    def broken_lamp(on: bool) -> None:
        carrier.log.append(f"lamp {'on' if on else 'off'}")
        if on:
            raise OSError("lamp relay driver not found")

    carrier.lamp = broken_lamp  # type: ignore[method-assign]
    report = arm_self_test(carrier, ARM, VirtualClock())
    assert not report.ok
    assert report.aborted == "OSError: lamp relay driver not found"
    assert len(report.checks) == 1 and report.checks[0].ok  # the pose reached is still reported
    assert "park" not in carrier.log and carrier.log[-2:] == ["stop", "close"]


def test_park_after_session_off_is_respected() -> None:
    carrier = FakeCarrier()
    report = arm_self_test(carrier, ARM, VirtualClock(), park=False)
    assert report.ok
    assert "park" not in carrier.log
    assert report.end is not None and report.end.outcome == "left"
    (line,) = [x for x in report.lines() if "parked" in x]
    assert line.startswith("NOT parked (park_after_session is off); left at az "), line


def test_the_real_driver_is_not_parked_after_an_error(tmp_path: Path) -> None:
    """Emulated XL430s through the real SDK: a move that fails (an obstruction, say) leaves the
    arm where it stopped — the driver's close must not park it behind the test's back."""
    from rti_rig.app.compose import build_rig
    from rti_rig.app.config import load_rig_config

    with build_rig(load_rig_config(inprocess_arm_config(tmp_path))) as rig:
        carrier = rig.lighting.carrier  # type: ignore[attr-defined]
        emulator = rig.emulator  # type: ignore[attr-defined]
        real_move, moves = carrier.move_to, []

        def move_until_blocked(direction: np.ndarray) -> np.ndarray:
            moves.append(direction)
            if len(moves) == 3:
                raise DeviceError(carrier.name, "not in position after 5 s: obstructed?")
            return real_move(direction)

        carrier.move_to = move_until_blocked
        report = arm_self_test(carrier, rig.geometry, rig.clock)  # type: ignore[arg-type]
        assert not report.ok and "obstructed" in (report.aborted or "")
        ticks = tuple(round(v) for v in emulator.joint_positions().values())
        park = carrier.kin.ticks_of_pose(0.0, 10.0)
        assert max(abs(a - b) for a, b in zip(ticks, park, strict=True)) > 20
        assert not carrier.lamp_is_on


def test_a_refused_pose_stops_the_test_before_anything_connects() -> None:
    carrier = FakeCarrier(refuse=True)
    report = arm_self_test(carrier, ARM, VirtualClock())
    assert not report.ok
    assert "refused before moving" in (report.aborted or "")
    assert carrier.log == []


@pytest.mark.e2e
@pytest.mark.parametrize(
    "config",
    [
        "virtual_arm.toml",
        pytest.param("simulated_arm.toml", marks=pytest.mark.pty),
        "simulated_arm.toml (inprocess)",
    ],
)
def test_check_command_on_the_shipped_arm_configs(config: str, tmp_path: Path) -> None:
    """The pure simulated arm and the emulated Dynamixel arm (real driver and SDK, on the pty
    as shipped and in-process) all pass."""
    path = inprocess_arm_config(tmp_path) if "inprocess" in config else CONFIGS / config
    r = runner.invoke(app, ["check", str(path)])
    assert r.exit_code == 0, r.output
    assert "RESULT: PASS" in r.output
    # parked as read back at the park pose (the check had said "parked" of any park that
    # returned, without reading where the arm was)
    park_el = 45.0 if config == "virtual_arm.toml" else 10.0
    assert "8 poses" in r.output and "NOT parked" not in r.output
    assert (
        f"\nparked (read back at az 0.0°, el {park_el:.1f}°, within 1° of its park pose)\n"
        in r.output
    ), r.output
    assert r.output.count(" ok\n") == 8
    # the heading names the arm once ("arm arm: 8 poses" on the Dynamixel configs, whose
    # driver's arm is named "arm"; "arm simulated arm" on the virtual one)
    heading = "simulated arm" if config == "virtual_arm.toml" else "arm"
    assert f"\n{heading}: 8 poses, tolerance 1°\n" in r.output, r.output
    assert not re.search(r"\b(\w+) \1\b", r.output), r.output  # no word said twice


@pytest.mark.parametrize(
    ("name", "label"),
    [
        ("arm", "arm"),
        ("simulated arm", "simulated arm"),
        ("left-Arm", "left-Arm"),
        ("tablet-rig", "arm tablet-rig"),  # a name that does not say what it is gets the noun
        ("swarm", "arm swarm"),  # ... a word holding "arm" is no arm
    ],
)
def test_the_heading_names_the_arm_with_one_noun(name: str, label: str) -> None:
    report = arm_self_test(RenamedCarrier(name), ARM, VirtualClock())
    assert report.lines()[0] == f"{label}: 8 poses, tolerance 1°"


@pytest.mark.e2e
def test_check_command_fails_on_a_missing_config(tmp_path: Path) -> None:
    r = runner.invoke(app, ["check", str(tmp_path / "nope.toml")])
    assert r.exit_code != 0


@pytest.mark.e2e
def test_an_arm_whose_stop_failed_is_not_said_to_have_been_stopped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`rti-rig check` on the emulated arm (real driver and SDK, in-process) whose azimuth servo
    stops answering at the third pose: the teardown's stop cannot hold that joint, which may
    still be moving. The abort line had said "the arm was stopped where it was" above the
    teardown's "it may still be moving", and the close's repeat of the stop's failure was a
    second copy of the same paragraph."""
    from rti_rig.app import compose
    from rti_rig.app.usecases import check

    def build_rig(loaded, clock=None):  # type: ignore[no-untyped-def]
        rig = compose.build_rig(loaded, clock)
        carrier, emulator, moves = rig.lighting.carrier, rig.emulator, []  # type: ignore[attr-defined]
        real_move = carrier.move_to

        def move_to(direction: np.ndarray) -> np.ndarray:
            moves.append(direction)
            if len(moves) == 3:
                emulator.silent_ids.add(loaded.config.arm.dynamixel.azimuth.servo_id)
            return real_move(direction)

        carrier.move_to = move_to
        return rig

    monkeypatch.setattr(check, "build_rig", build_rig)
    r = runner.invoke(app, ["check", str(inprocess_arm_config(tmp_path))])
    said = " ".join(r.output.split())
    assert "RESULT: FAIL" in said and "NOT parked" in said
    assert "it may still be moving" in said  # the teardown's stop, as the driver said it
    assert "stopped where it was" not in said, said
    assert "the stop did not hold every joint" in said
    assert said.count("it may still be moving") == 1, said
    assert "teardown FAILED: close: failed with the same error as 'stop' above" in said
