"""What ``run`` says, and the manifest records, of where an arm was left, and of its moves.

Every arm session had ended with "lamp off and stop were requested" whether the arm had
parked, had been left where it stopped (``park_after_session = false``, an emergency stop) or
had failed to park; a completed run on the simulated arm said nothing at all; the manifest
recorded none of it; and the time spent moving the arm was said nowhere. Each case runs the
CLI on a shipped arm config; a stop or a fault is raised at a known call, not by a timer.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO, pasted, servo_fault

from rti_rig.core.shell_words import shell_word

#: runs rti-rig with, as the environment asks, a SIGTERM sent to itself as the arm is about
#: to light the Nth image (``ARM_END_SIGTERM_AT``), or the park failing (``ARM_END_JAM``)
HOOK = """
import os, signal, sys
from rti_rig.runtime.lighting import ArmLighting
at = int(os.environ.get("ARM_END_SIGTERM_AT", "0"))
real_set = ArmLighting.set
calls = []
def hooked_set(self, step):
    calls.append(step)
    if len(calls) == at:
        os.kill(os.getpid(), signal.SIGTERM)
    return real_set(self, step)
ArmLighting.set = hooked_set
if os.environ.get("ARM_END_JAM"):
    real_safe = ArmLighting.safe
    def jammed_safe(self, emergency=False):
        def jam(cancelled=None):
            raise RuntimeError("jammed")
        self.carrier.park = jam
        return real_safe(self, emergency)
    ArmLighting.safe = jammed_safe
from rti_rig.cli import app
sys.argv = ["rti-rig", *sys.argv[1:]]
app()
"""


def _config(tmp_path: Path, shipped: str, arm_line: str = "") -> Path:
    """The shipped config ``shipped``, with ``arm_line`` added under its ``[arm]``."""
    text = (CONFIGS / shipped).read_text()
    if arm_line:
        assert "\n[arm]\n" in text
        text = text.replace("\n[arm]\n", f"\n[arm]\n{arm_line}\n", 1)
    cfg = tmp_path / shipped
    cfg.write_text(text)
    return cfg


def _run(tmp_path: Path, cfg: Path, lights: int = 4, **env: str) -> tuple[int, str, Path]:
    """``rti-rig run cfg`` (hooked as ``env`` asks): exit code, output folded, session."""
    hook = tmp_path / "hook.py"
    hook.write_text(HOOK)
    out = tmp_path / "s"
    argv = ["run", str(cfg), "--lights", str(lights), "--out", str(out), "--no-verdict"]
    proc = subprocess.run(
        [sys.executable, str(hook), *argv],
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300", **env},
        capture_output=True,
        text=True,
        timeout=600,
    )
    return proc.returncode, " ".join((proc.stdout + proc.stderr).split()), out


def _arm_end(out: Path) -> dict:  # type: ignore[type-arg]
    return json.loads((out / "manifest.json").read_text())["runner"]["arm_end"]


@pytest.mark.parametrize(
    ("shipped", "park_el"), [("simulated_arm.toml", 10.0), ("virtual_arm.toml", 45.0)]
)
def test_a_completed_run_says_the_arm_parked_where_read_back_and_its_moving_time(
    tmp_path: Path, shipped: str, park_el: float
) -> None:
    code, said, out = _run(tmp_path, _config(tmp_path, shipped))
    assert code == 0, said
    assert (
        f"lamp off and stop were requested; the arm parked (read back at az 0.0°, "
        f"el {park_el:.1f}°, within 1° of its park pose)." in said.lower()
    ), said
    end = _arm_end(out)
    assert end["outcome"] == "parked" and end["elevation_deg"] == pytest.approx(park_el, abs=1)
    # the moves: each image's start to lamp-on, summed, said beside the session time
    records = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    steps = [r for r in records if "light_s" in r]
    moving = sum(r["light_s"] for r in steps)
    assert moving > 0
    # the emulated arm's lamp = "software" is switched by no command of rti-rig: the lamp-on
    # is said only of the simulated arm's lamp, which is (it had been said of both)
    lamp = "" if shipped == "simulated_arm.toml" else " (and switching its lamp on)"
    assert f"of which moving the arm{lamp} {moving:.1f} s" in said, said
    assert ("switching its lamp" in said) == bool(lamp), said
    # and the park at the end, the rest of the session's time after its last image (it had
    # been left out: a 2 s park on a 21 s session was time no line accounted for)
    last = steps[-1]
    after_last = json.loads((out / "manifest.json").read_text())["runs"][0]["rig_time_s"] - (
        last["rig_start_s"] + last["light_s"] + last["settle_s"] + last["capture_s"]
    )
    parking = re.search(r"s, and parking it (\d+\.\d) s", said)
    assert parking is not None, said
    # the rest beyond the park (said to the tenth) is the teardown's few exchanges on the bus,
    # lamp off, stop, read-back and close (0.06 s at simulated_arm.toml's 57600 baud)
    assert after_last > 0.5 and -0.05 <= after_last - float(parking[1]) < 0.15, said
    if shipped == "virtual_arm.toml":  # the rig bench tradeoff times its arm column on
        _the_benchmark_times_the_arm_as_run_does(out)


def _the_benchmark_times_the_arm_as_run_does(out: Path) -> None:
    """``bench tradeoff``'s arm time for this session's lights is the dry run's own session
    time: the same shipped config's timing (its arm column had counted the dome's 0.1 s
    settle where virtual_arm.toml settles 0.3 s, and one lamp switch a light of run's two),
    the same order, the same moves and park."""
    import numpy as np

    from benchmarks.tradeoff import ARM_CONFIG, DOME_CONFIG, session_times, shipped_rig

    lines = (out / "lights.lp").read_text().splitlines()[1:]
    dirs = np.array([[float(v) for v in line.split()[1:4]] for line in lines])
    _, arm_s = session_times(dirs, shipped_rig(DOME_CONFIG), shipped_rig(ARM_CONFIG))
    rig_s = json.loads((out / "manifest.json").read_text())["runs"][0]["rig_time_s"]
    assert arm_s == pytest.approx(rig_s, abs=0.01), (arm_s, rig_s)


def test_a_run_with_park_off_says_where_the_arm_is_left(tmp_path: Path) -> None:
    cfg = _config(tmp_path, "simulated_arm.toml", "park_after_session = false")
    code, said, out = _run(tmp_path, cfg)
    assert code == 0, said
    end = _arm_end(out)
    assert end["outcome"] == "left" and end["why"] == "park_after_session is off"
    at = f"az {end['azimuth_deg']:.1f}°, el {end['elevation_deg']:.1f}°"
    assert (
        f"the arm was not parked and is left at {at} (read back; park_after_session is off)" in said
    ), said
    assert abs(end["elevation_deg"] - 10.0) > 1  # not at the park pose: it stayed put


def test_a_sigterm_with_park_on_emergency_says_the_arm_parked(tmp_path: Path) -> None:
    cfg = _config(tmp_path, "simulated_arm.toml", "park_on_emergency_stop = true")
    code, said, out = _run(tmp_path, cfg, ARM_END_SIGTERM_AT="3")
    assert code == 143, said
    assert (
        "Emergency stop (SIGTERM): lamp off and stop were requested; the arm parked "
        "(read back at az 0.0°, el 10.0°" in said
    ), said
    assert _arm_end(out)["outcome"] == "parked"


def test_a_sigterm_on_the_virtual_arm_says_it_is_left_where_it_stopped(tmp_path: Path) -> None:
    code, said, out = _run(tmp_path, _config(tmp_path, "virtual_arm.toml"), ARM_END_SIGTERM_AT="3")
    assert code == 143, said
    end = _arm_end(out)
    assert end["outcome"] == "left" and end["azimuth_deg"] is not None
    assert "the arm was not parked and is left at az " in said, said
    assert "park_on_emergency_stop is off" in said, said


def test_each_run_of_a_resumed_session_keeps_where_it_left_the_arm(tmp_path: Path) -> None:
    """The manifest's ``runner`` is the last run's alone (a resume resets it), so a session
    stopped with the arm left mid-band and then resumed to its park had kept only "parked":
    each run's record now stays with it, under ``runs[i].arm_end``."""
    cfg = _config(tmp_path, "virtual_arm.toml")
    code, said, out = _run(tmp_path, cfg, ARM_END_SIGTERM_AT="3")
    assert code == 143, said
    hook = tmp_path / "hook.py"
    proc = subprocess.run(
        [sys.executable, str(hook), "run", "--resume", str(out), "--no-verdict"],
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"},
        capture_output=True,
        text=True,
        timeout=600,
    )
    said = " ".join((proc.stdout + proc.stderr).split())
    assert proc.returncode == 0, said
    runs = json.loads((out / "manifest.json").read_text())["runs"]
    assert [r["finish_reason"] for r in runs] == ["emergency-stop", "completed"]
    assert runs[0]["arm_end"]["outcome"] == "left" and runs[0]["arm_end"]["azimuth_deg"] is not None
    assert runs[1]["arm_end"]["outcome"] == "parked"
    assert _arm_end(out) == runs[1]["arm_end"]


def test_a_park_that_fails_is_said_not_confirmed(tmp_path: Path) -> None:
    code, said, out = _run(tmp_path, _config(tmp_path, "virtual_arm.toml"), ARM_END_JAM="1")
    assert code == 1, said  # complete, but not brought to a known safe state
    assert "the arm's park is NOT confirmed: the park failed (park: jammed); read back at" in said
    end = _arm_end(out)
    assert end["outcome"] == "park-unconfirmed" and "jammed" in end["why"]


def test_a_fault_that_blocks_the_park_is_said_once(tmp_path: Path) -> None:
    """Servo 2 overloads mid-run (its torque off): the park is not attempted. Why had been
    said twice (a "park: not attempted because …" teardown problem, then the arm's sentence
    "park is NOT confirmed: not attempted because …"), and the fault's paragraph of what to do
    twice too (in the teardown's stop, then in the error)."""
    # in a folder whose name a shell splits: the check to paste names it as one word
    (tmp_path / "arm rig").mkdir()
    cfg = _config(tmp_path / "arm rig", "simulated_arm.toml")
    with cfg.open("a") as f:
        f.write(servo_fault(200, 2))
    code, said, out = _run(tmp_path, cfg, lights=6)
    assert code == 2, said
    assert "Traceback" not in said
    assert said.count("not attempted because the arm's own move failed") == 1, said
    assert (
        "the arm's park is NOT confirmed: not attempted because the arm's own move failed: "
        "parking is a move of both joints" in said
    ), said
    # what to do, in order: the stop did not hold servo 2, so the power goes off first (as
    # the lights line says), and comes back on before the park ("then park it with 'rti-rig
    # check'" had followed "switch the arm's power supply off"); the park's check names the
    # rig config, ready to paste (a bare 'rti-rig check' is refused for its missing config)
    assert (
        "Support the lamp and switch the arm's power off first (a joint the stop did not hold "
        "may still be moving, or sag); then clear the fault (its error says how), switch the "
        f"power back on and park it with rti-rig check {shell_word(cfg)} --park-only " in said
    ), said
    assert pasted(shell_word(cfg).encode()) == bytes(cfg)
    assert said.count("clear the obstruction") == 1, said  # in the error, said last
    assert said.rindex("clear the obstruction") > said.index("(as in the error below)"), said
    assert _arm_end(out)["outcome"] == "park-unconfirmed"


def test_a_dome_s_time_line_says_nothing_of_moving(tmp_path: Path) -> None:
    """The moving time is an arm's: a dome's session time has no such part."""
    code, said, _ = _run(tmp_path, _config(tmp_path, "simulated_dome.toml"))
    assert code == 0, said
    assert "Session time on the real rig" in said and "moving the arm" not in said, said
