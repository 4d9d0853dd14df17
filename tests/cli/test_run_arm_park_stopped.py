"""A Ctrl-C or SIGTERM during an arm session's final park stops the arm where it is, held.

The teardown holds Ctrl-C and SIGTERM (a stop must not cut the lamp-off), and the park ran
inside that hold: a user's stop during it was sat out until the arm had parked (up to
``move_timeout_s``, 20 s on the shipped config), and the run then said "parked". Each case
runs ``rti-rig run`` on the shipped emulated arm in a subprocess sent a real signal once the
emulated elevation servo reports it is moving to the park pose; the rig runs on the wall
clock (a dry run's virtual clock would finish the park before any signal could come) with
the elevation joint slowed (1 rpm: the park takes seconds) so that the signal comes mid-park.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO

#: runs rti-rig on the wall clock; says "PARK MOVING" once the emulated elevation servo moves
#: to the park pose, "PARK ENDED <monotonic s>" when the driver's park returns or raises, and
#: after the teardown "SERVOS {...}": the emulated servos' Torque Enable and Goal Position, and
#: the park's goal
HOOK = """
import json, sys, threading, time
import rti_rig.app.compose as compose
from rti_rig.core.clock import SystemClock
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.runtime.lighting import ArmLighting
rigs = []
real_build = compose.build_rig
def build_rig(loaded, clock=None):
    rigs.append(real_build(loaded, clock or SystemClock()))
    return rigs[-1]
compose.build_rig = build_rig
real_park = DynamixelArm.park
def park(self, *args, **kwargs):
    servo = rigs[-1].emulator.servos[2]
    def watch():
        deadline = time.monotonic() + 120
        while not servo.is_moving() and time.monotonic() < deadline:
            time.sleep(0.01)
        print("PARK MOVING", file=sys.stderr, flush=True)
    threading.Thread(target=watch, daemon=True).start()
    try:
        return real_park(self, *args, **kwargs)
    finally:
        print(f"PARK ENDED {time.monotonic()}", file=sys.stderr, flush=True)
real_safe = ArmLighting.safe
def safe(self, *args, **kwargs):
    # after the teardown's read-back, a request answered on the same link: any goal written
    # before it has reached the emulated servos (a Sync Write is not answered)
    try:
        return real_safe(self, *args, **kwargs)
    finally:
        s = self.carrier.settings
        park_goal = self.carrier.kin.ticks_of_pose(s.park_azimuth_deg, s.park_elevation_deg)
        servos = [rigs[-1].emulator.servos[j.servo_id] for j in s.joints]
        state = {
            "torque": [x.get(ct.TORQUE_ENABLE) for x in servos],
            "goal": [x.get(ct.GOAL_POSITION) for x in servos],
            "park": list(park_goal),
        }
        print("SERVOS " + json.dumps(state), file=sys.stderr, flush=True)
ArmLighting.safe = safe
DynamixelArm.park = park
from rti_rig.cli import app
sys.argv = ["rti-rig", *sys.argv[1:]]
app()
"""


def _slow_config(tmp_path: Path) -> Path:
    """The shipped emulated arm, its elevation joint at 1 rpm (6°/s) and the timeout raised
    to match (the config check refuses a timeout shorter than the longest move)."""
    text = (CONFIGS / "simulated_arm.toml").read_text()
    head, sep, elevation = text.partition("[arm.dynamixel.elevation]")
    assert sep and "profile_velocity_rpm = 20.0" in elevation
    elevation = elevation.replace("profile_velocity_rpm = 20.0", "profile_velocity_rpm = 1.0", 1)
    assert "move_timeout_s = 20.0" in head
    head = head.replace("move_timeout_s = 20.0", "move_timeout_s = 40.0", 1)
    cfg = tmp_path / "slow_arm.toml"
    cfg.write_text(head + sep + elevation)
    return cfg


def _run_signalled(tmp_path: Path, *signals: int) -> tuple[int, str, Path, float, dict]:  # type: ignore[type-arg]
    """``rti-rig run`` sent ``signals[0]`` once the park moves, the rest once the park
    has ended: exit code, output folded,
    session, seconds from the first signal to the park's end (the child's monotonic clock
    is the system's, as this one's), and the emulated servos' state as the park ended."""
    hook = tmp_path / "hook.py"
    hook.write_text(HOOK)
    out = tmp_path / "s"
    argv = ["run", str(_slow_config(tmp_path)), "--lights", "2", "--out", str(out)]
    proc = subprocess.Popen(
        [sys.executable, str(hook), *argv, "--no-verdict"],
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"},
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    lines: list[str] = []
    sent_at = None
    # the reads below block until the child writes or exits: one that never exits (a stop
    # that hangs) is killed, and the test fails on what it said, rather than hanging for ever
    watchdog = threading.Timer(300, proc.kill)
    watchdog.start()
    try:
        assert proc.stdout is not None
        for line in proc.stdout:  # until the park moves (or the run ends without one)
            lines.append(line)
            if line.startswith("PARK MOVING"):
                sent_at = time.monotonic()
                proc.send_signal(signals[0])
            elif line.startswith("PARK ENDED"):
                # any further signal once the first has been acted on (two sent at once are
                # one: a process sees a pending signal once)
                for sig in signals[1:]:
                    proc.send_signal(sig)
                break
        lines.append(proc.stdout.read())
        code = proc.wait(timeout=300)
    finally:
        watchdog.cancel()
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    said = "".join(lines)
    assert sent_at is not None, said
    ended = [float(x.split()[2]) for x in said.splitlines() if x.startswith("PARK ENDED")]
    assert ended, said
    servos = [json.loads(x[len("SERVOS ") :]) for x in said.splitlines() if x.startswith("SERVOS")]
    assert servos, said
    return code, " ".join(said.split()), out, ended[0] - sent_at, servos[0]


def _arm_end(out: Path) -> dict:  # type: ignore[type-arg]
    return json.loads((out / "manifest.json").read_text())["runner"]["arm_end"]


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize(
    ("signals", "code", "who"),
    [
        ((signal.SIGINT,), 130, "Ctrl-C"),
        ((signal.SIGINT, signal.SIGINT), 130, "Ctrl-C"),
        ((signal.SIGTERM,), 143, "SIGTERM"),
    ],
    ids=["ctrl-c", "ctrl-c-twice", "sigterm"],
)
def test_a_stop_during_the_final_park_holds_the_arm_where_it_is(
    tmp_path: Path, signals: tuple[int, ...], code: int, who: str
) -> None:
    got, said, out, took, servos = _run_signalled(tmp_path, *signals)
    print(f"park ended {took:.3f} s after the signal")
    assert got == code, said
    assert "Traceback" not in said, said
    # held, not let go: torque on at both servos, the elevation's goal rewritten off the park
    assert servos["torque"] == [1, 1], servos
    assert abs(servos["goal"][1] - servos["park"][1]) > 20, servos
    end = _arm_end(out)
    # held part-way: read back, away from the park pose (el 10°), not "parked"
    assert end["outcome"] == "left", said
    assert end["elevation_deg"] is not None and end["elevation_deg"] > 12.0, end
    assert end["why"] == f"the park was stopped by {who}: held where it stopped, torque on"
    at = f"az {end['azimuth_deg']:.1f}°, el {end['elevation_deg']:.1f}°"
    assert f"the arm was not parked and is left at {at} (read back; the park was stopped" in said
    assert "parked (read back" not in said and "Stopping after this image" not in said, said
    # its seconds are in the session's time line, not said as a park done
    if "of which moving the arm" in said:
        assert "parking it" not in said and "its park, cut short," in said, said
    # nothing captured is lost: both images kept and listed
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["steps_done_this_run"] == 2, said
    assert len((out / "lights.lp").read_text().split("\n")[1:]) >= 2
    stopped = "Stopped (Ctrl-C) during the arm's park, once the session had ended" in said
    if signals == (signal.SIGINT,):
        assert stopped, said
    elif signals == (signal.SIGTERM,):  # the run's emergency stop, said as ever
        assert "Emergency stop (SIGTERM)" in said, said
        # of a session whose images are all in: complete, fit next (it had said "Continue
        # with: rti-rig run --resume", with nothing left to resume)
        assert "the session is complete" in said and f"rti-rig fit {out}" in said, said
        assert "--resume" not in said, said
    else:  # the second Ctrl-C, delivered once the teardown is done, stops nothing more: the
        # park's stop is said as the first's (it had been "Emergency stop (second Ctrl-C)",
        # the manifest's end a completed run's)
        assert stopped and "Emergency stop" not in said, said


#: a dry run of the simulated arm whose Ctrl-C comes in the teardown but stops no park: raised
#: by the arm's own stop (no park due: park_after_session is off) or once its park has returned
LATE_HOOK = """
import os, signal, sys
from rti_rig.runtime.lighting import ArmLighting
from rti_rig.simulator.sim_lights import SimulatedArm
when = os.environ["CTRL_C_AT"]
tearing = []
real_safe = ArmLighting.safe
def safe(self, *args, **kwargs):
    tearing.append(1)
    return real_safe(self, *args, **kwargs)
ArmLighting.safe = safe
real_stop, real_park = SimulatedArm.stop, SimulatedArm.park
def stop(self):
    real_stop(self)
    if tearing and when == "stop":
        signal.raise_signal(signal.SIGINT)
def park(self, *args, **kwargs):
    real_park(self, *args, **kwargs)
    if when == "parked":
        signal.raise_signal(signal.SIGINT)
SimulatedArm.stop, SimulatedArm.park = stop, park
from rti_rig.cli import app
sys.argv = ["rti-rig", *sys.argv[1:]]
app()
"""


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize(
    ("when", "outcome"), [("stop", "left"), ("parked", "parked")], ids=["no-park-due", "parked"]
)
def test_a_ctrl_c_in_a_teardown_that_stops_no_park_is_not_said_to_have(
    tmp_path: Path, when: str, outcome: str
) -> None:
    """A Ctrl-C held by the teardown when no park was due (park_after_session = false), or
    after the park had ended, stopped no park: the run had said "Stopped (Ctrl-C) during the
    arm's park" of an arm it had just said was left by policy, or parked."""
    text = (CONFIGS / "virtual_arm.toml").read_text()
    if when == "stop":
        assert "\ndefault_lights = 24\n" in text
        text = text.replace(
            "\ndefault_lights = 24\n", "\ndefault_lights = 24\npark_after_session = false\n", 1
        )
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text)
    out = tmp_path / "s"
    code, said = _run_late(tmp_path, when, "run", str(cfg), "--lights", "2", "--out", str(out))
    assert "Traceback" not in said, said
    assert _arm_end(out)["outcome"] == outcome, said
    assert "during the arm's park" not in said, said
    # the images were all in: there was no image to stop after (it had said "Stopping after
    # this image (Ctrl-C again to stop at once)")
    assert "Stopping after this image" not in said, said
    assert "Ctrl-C after the capture had ended: there was nothing left to stop" in said, said
    assert code == 0, said


def _run_late(tmp_path: Path, when: str, *argv: str) -> tuple[int, str]:
    """``rti-rig ARGV`` under :data:`LATE_HOOK` (its Ctrl-C raised ``when``): exit code and
    output folded."""
    hook = tmp_path / "hook.py"
    hook.write_text(LATE_HOOK)
    done = subprocess.run(
        [sys.executable, str(hook), *argv, *(["--no-verdict"] if argv[0] == "run" else [])],
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300", "CTRL_C_AT": when},
        capture_output=True,
        text=True,
        timeout=300,
    )
    return done.returncode, " ".join((done.stdout + done.stderr).split())


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_that_stops_a_preview_s_park_keeps_its_plan_hint(tmp_path: Path) -> None:
    """``rti-rig preview`` on an arm, a Ctrl-C as its teardown stops the arm (its park then not
    begun): it had ended as a run does, "its QA verdict was not computed: rti-rig fit … gives
    it" (a preview has none), and without its "Plan from it" line."""
    out = tmp_path / "p"
    code, said = _run_late(
        tmp_path, "stop", "preview", str(CONFIGS / "virtual_arm.toml"), "--out", str(out)
    )
    assert code == 130, said
    assert "Traceback" not in said, said
    assert "read back; the park was stopped by Ctrl-C: held where it stopped" in said, said
    assert f"Plan from it: rti-rig plan {out} --rig " in said, said
    assert "verdict" not in said and "rti-rig fit" not in said, said
    assert (
        f"Stopped (Ctrl-C) during the arm's park, once the preview had ended: it is complete "
        f"in {out} (plan from it as above)" in said
    ), said
