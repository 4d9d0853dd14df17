"""A run whose end a stop cut (the controller's teardown never ran, so it never recorded the
run's end) is recorded on disk as stopped, so that a later ``--resume`` says "stopped",
and "killed" only of a run killed outright.

A SIGTERM as the teardown begins (as it marks the capture over, before its hold) had been such
a cut; the controller now catches a stop there and runs its teardown for it (the run's end
recorded, its times known): the first test shows that. The cut is then made by a stop raised
where the teardown sets its hold, in its place (:func:`_teardown_cut`), for the session's close,
the safety net for a teardown that did not run whatever cut it.

The teardown's end record (:meth:`SessionFolder.finish`) is written only by the controller:
where a stop cut it, the session's close made the devices safe in its place and wrote nothing,
and the run's manifest entry was left as a SIGKILL leaves it. The resume then said "1 run(s)
killed before recording their time" of a run the user had stopped with a SIGTERM.

An arm's run cut at the same moment: the session's close switches its lamp off (the carrier's
close sends the lamp-off and the stop while it is connected), checked on the emulated servo.
"""

from __future__ import annotations

import json
import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, inprocess_arm_config, opened_session_kept
from conftest import said as unwrapped
from typer.testing import CliRunner

import rti_rig.runtime.controller as controller
from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.runtime.session import SessionFolder

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")


def _sigterm_as_the_teardown_begins(monkeypatch: pytest.MonkeyPatch) -> None:
    """A real SIGTERM, raised in the run's own process in the controller's ``finally``
    before it holds signals (as it marks the capture over): no timing."""
    real_over = controller.CancelToken.capture_over

    def capture_over(self) -> None:  # type: ignore[no-untyped-def]
        signal.raise_signal(signal.SIGTERM)
        real_over(self)

    monkeypatch.setattr(controller.CancelToken, "capture_over", capture_over)


def _teardown_cut(monkeypatch: pytest.MonkeyPatch, before: Any = None) -> None:
    """A real SIGTERM raised where the controller's teardown sets its hold, in its place: the
    handler's EmergencyStop leaves the ``finally`` and the teardown does not run (``before``,
    if given, is called first)."""
    real_held = controller._teardown_held

    def teardown_held(cancel: Any) -> Any:
        if before is not None:
            before()
        signal.raise_signal(signal.SIGTERM)
        return real_held(cancel)

    monkeypatch.setattr(controller, "_teardown_held", teardown_held)


def test_a_sigterm_as_the_teardown_begins_gets_the_teardown_and_its_end_recorded(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before, the stop left the controller's ``finally`` before its hold: no teardown of the
    controller's, the run's end cut (its times unknown), the session's close in its place."""
    out = tmp_path / "s"
    with monkeypatch.context() as patched:
        _sigterm_as_the_teardown_begins(patched)
        r, said = _run(CONFIGS / "emulated_dome.toml", out)
    assert r.exit_code == 143, said
    assert "Emergency stop (SIGTERM)" in said and "6 image(s) kept" in said, said
    assert "Traceback" not in said and "teardown problem" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    (run,) = manifest["runs"]
    assert run["finish_reason"] == "emergency-stop" and not run.get("end_cut"), run
    assert "rig_time_s" in run, run
    runner = manifest["runner"]
    assert runner["error"] == "emergency stop: SIGTERM", runner
    assert runner["steps_done_this_run"] == 6, runner


def _run(config: Path, out: Path, *more: str) -> tuple[Any, str]:
    argv = ["run", str(config), "--lights", "6", "--out", str(out), "--no-verdict", *more]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    return r, unwrapped(r)


def test_a_run_whose_end_a_stop_cut_is_resumed_as_stopped_not_killed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "s"
    with monkeypatch.context() as patched:
        _teardown_cut(patched)
        r, said = _run(CONFIGS / "emulated_dome.toml", out)
    assert r.exit_code == 143, said
    assert "Emergency stop (SIGTERM)" in said and "6 image(s) kept" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    (run,) = manifest["runs"]
    assert run["finish_reason"] == "emergency-stop" and run["end_cut"] is True, run
    assert "rig_time_s" not in run  # not known where the stop cut the end: not made up
    assert manifest["runner"]["finish_reason"] == "emergency-stop", manifest["runner"]
    # the images committed when the stop came; the steps themselves stay for the resume
    assert manifest["runner"]["steps_done"] == 6 and manifest.get("steps") == [], manifest
    assert manifest["runner"]["steps_planned"] == 6, manifest["runner"]

    # the verdict (a QA of the session's images, seconds under load) is not what this shows:
    # the resume's opening words are
    argv = ["run", "--resume", str(out), "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    said = unwrapped(r)
    assert r.exit_code == 0, said
    assert "6 image(s) in the session" in said, said
    assert "1 run(s) stopped before recording their time" in said, said
    assert "killed" not in said, said


def test_an_arm_run_whose_end_a_stop_cut_has_its_lamp_switched_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The lamp on the elevation servo's LED, lit for each image: the stop lands as the
    teardown begins, and the session's close (not the teardown) switches it off."""
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text()
    assert 'lamp = "software"' in text
    cfg.write_text(text.replace('lamp = "software"', 'lamp = "servo_led"\nlamp_servo_id = 2'))
    seen = opened_session_kept(monkeypatch)
    lit: list[int] = []

    def lamp_lit() -> None:
        # the lamp as the stop lands: lit again here, as a stop during an image leaves it
        emulator = seen["opened"].rig.emulator
        emulator.servos[2]._set(ct.LED, 1)
        lit.append(emulator.servos[2].get(ct.LED))

    _teardown_cut(monkeypatch, lamp_lit)
    real_record = SessionFolder.record_cut_end

    def record_cut_end(self: SessionFolder, reason: str, *more: Any) -> bool:
        # the lamp as the stop is written down: off already (safety before the disk's fsync)
        lit.append(seen["opened"].rig.emulator.servos[2].get(ct.LED))
        return real_record(self, reason, *more)

    monkeypatch.setattr(SessionFolder, "record_cut_end", record_cut_end)
    r, said = _run(cfg, tmp_path / "s")
    assert r.exit_code == 143, said
    assert lit == [1, 0], said
    assert seen["opened"].rig.emulator.servos[2].get(ct.LED) == 0, said  # switched off
    assert "Emergency stop (SIGTERM): lamp off and stop were requested" in said, said
    assert "teardown problem" not in said and "Traceback" not in said, said
    manifest = json.loads((tmp_path / "s" / "manifest.json").read_text())
    assert manifest["runs"][-1]["finish_reason"] == "emergency-stop", manifest["runs"]
