"""A stop (a second Ctrl-C, a SIGTERM) landing as ``run`` reports a capture that has ended —
in its except clauses or its ``finally``, before Ctrl-C is ignored — neither escapes as a
traceback nor cuts what the run says of the images, the lights and how to go on.

The capture's handlers stayed in place there: a second Ctrl-C (or a SIGTERM) raised
EmergencyStop where nothing caught it, and ``rti-rig`` printed Python's traceback instead of
the summary or the error's resume hint. The signals are raised at exactly those points by the
function the run calls there (no sleep)."""

from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.cli.session as cli_session
import rti_rig.runtime.controller as controller
from rti_rig.cli import app
from rti_rig.core.errors import CaptureError

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")


def _ctrl_c_as(monkeypatch: pytest.MonkeyPatch, owner: Any, name: str, times: int = 1) -> None:
    """``owner.name`` begins with ``times`` Ctrl-C (SIGINT raised in this process, as the
    terminal sends it), then runs as it would: a Ctrl-C at that moment of the run."""
    real = getattr(owner, name)

    def pressed(*args: Any, **kwargs: Any) -> Any:
        for _ in range(times):
            signal.raise_signal(signal.SIGINT)
        return real(*args, **kwargs)

    monkeypatch.setattr(owner, name, pressed)


def _first_ctrl_c_at_image(monkeypatch: pytest.MonkeyPatch, image: int) -> None:
    """A Ctrl-C as image ``image`` (1-based) is shot: the run stops after it."""
    real_shoot, shots = controller.shoot_step, []

    def shoot_step(*args: Any, **kwargs: Any) -> Any:
        shots.append(1)
        if len(shots) == image:
            signal.raise_signal(signal.SIGINT)
        return real_shoot(*args, **kwargs)

    monkeypatch.setattr(controller, "shoot_step", shoot_step)


def _signal_as_ctrl_c_is_ignored(monkeypatch: pytest.MonkeyPatch, signum: int) -> list[int]:
    """``signum`` raised in ``_run_and_report``'s ``finally``, as it sets Ctrl-C ignored
    (before the ignore is in place): the window."""
    real_put_back, raised = cli_session.put_back, []

    def put_back(previous: Any) -> None:
        if not raised and previous.get(signal.SIGINT) is signal.SIG_IGN:
            raised.append(signum)
            signal.raise_signal(signum)
        real_put_back(previous)

    monkeypatch.setattr(cli_session, "put_back", put_back)
    return raised


def _run(tmp_path: Path) -> tuple[Any, str, Path]:
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    return r, " ".join(r.output.split()), out


def test_a_second_ctrl_c_in_the_finally_does_not_cut_the_summary(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _first_ctrl_c_at_image(monkeypatch, 2)
    raised = _signal_as_ctrl_c_is_ignored(monkeypatch, signal.SIGINT)
    r, said, out = _run(tmp_path)
    assert raised == [signal.SIGINT], said
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "Ctrl-C after the capture had ended: there was nothing left to stop" in said, said
    assert "2 image(s) in the session" in said, said
    assert "Lights were switched off" in said, said
    assert f"Continue with: rti-rig run --resume {out}" in said, said
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_sigterm_in_the_finally_is_said_after_the_summary(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    raised = _signal_as_ctrl_c_is_ignored(monkeypatch, signal.SIGTERM)
    r, said, _ = _run(tmp_path)
    assert raised == [signal.SIGTERM], said
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "6 image(s) in the session" in said, said
    assert "Stopped (SIGTERM) once the session had ended: it is complete" in said, said
    assert r.exit_code == 143, said
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def test_two_ctrl_c_as_a_failed_capture_is_reported_leave_the_error_and_resume_said(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The camera fails at image 3 of 6; two Ctrl-C land as the run reports it (in its
    except clause): the second had raised EmergencyStop out of it."""
    real_shoot, shots = controller.shoot_step, []

    def shoot_step(*args: Any, **kwargs: Any) -> Any:
        shots.append(1)
        if len(shots) == 3:
            raise CaptureError("camera", "no frame came (the cable was pulled)")
        return real_shoot(*args, **kwargs)

    monkeypatch.setattr(controller, "shoot_step", shoot_step)
    _ctrl_c_as(monkeypatch, cli_session, "_print_teardown_failures", times=2)
    r, said, out = _run(tmp_path)
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert said.count("Ctrl-C after the capture had ended") == 1, said
    assert f"2 image(s) kept in {out}" in said, said
    assert f"Continue with: rti-rig run --resume {out}" in said, said
    assert "error: camera: no frame came" in said, said
    assert r.exit_code == 2, said


def _ctrl_c_at_hand_over_then_two_as_it_closes(monkeypatch: pytest.MonkeyPatch) -> None:
    """A Ctrl-C held by the hand-over (the capture never begins), then two more as the session
    stopped before its capture closes its rig. (The new session's test and the resume's had
    each written it out.)"""
    _ctrl_c_as(monkeypatch, cli_session, "_execute")  # held by the hand-over: no capture
    _ctrl_c_as(monkeypatch, cli_session, "_stopped_before_capture", times=2)


def test_two_ctrl_c_as_a_session_stopped_before_its_capture_closes_are_answered(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A Ctrl-C at the hand-over stops the session before its first image; two more as its
    rig is closed had been told "Stopping after this image", then raised EmergencyStop out
    of the except clause that closes it."""
    _ctrl_c_at_hand_over_then_two_as_it_closes(monkeypatch)
    r, said, out = _run(tmp_path)
    assert not (out / "lights.lp").exists(), said  # nothing was captured
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "Stopping after this image" not in said, said
    assert said.count("Ctrl-C while the session stopped before its first image") == 1, said
    assert "Stopped (Ctrl-C) before the first image: nothing was captured" in said, said
    assert r.exit_code == 130, said


@pytest.mark.skipif(not hasattr(signal, "SIGUSR1"), reason="no SIGUSR1")
def test_a_pause_asked_as_the_end_is_reported_is_said_to_be_ignored(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """SIGUSR1 (pause) in the same window, once every image is in: it had been told "Pausing
    after this image", of a session with no image left to pause before."""
    raised = _signal_as_ctrl_c_is_ignored(monkeypatch, signal.SIGUSR1)
    r, said, _ = _run(tmp_path)
    assert raised == [signal.SIGUSR1], said
    assert r.exit_code == 0, said
    assert "Pausing after this image" not in said, said
    assert "SIGUSR1 ignored: a session pauses only while it captures." in said, said
    assert "6 image(s) in the session" in said, said


def test_two_ctrl_c_as_a_resume_stopped_before_it_went_on_closes_are_not_told_first_image(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same of a resume (its first 2 images in): the Ctrl-C as its rig closes had been told
    "the session stopped before its first image", of a session with images kept."""
    _first_ctrl_c_at_image(monkeypatch, 2)
    r, said, out = _run(tmp_path)
    assert r.exit_code == 130 and "2 image(s) in the session" in said, said
    monkeypatch.undo()
    _ctrl_c_at_hand_over_then_two_as_it_closes(monkeypatch)
    argv = ["run", "--resume", str(out), "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "first image" not in said, said
    assert said.count("Ctrl-C while the resumed session stopped before it went on") == 1, said
    assert "Stopped (Ctrl-C) before the session went on: no new image was captured" in said, said
    assert r.exit_code == 130, said


def test_a_ctrl_c_once_the_stop_said_the_lights_points_above(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two Ctrl-C at image 3 stop the run at once; a third as the stop reads what the folder
    holds, after its line of the lights: it had said the teardown's doing was "said below",
    above the images kept and the resume."""
    real_shoot, shots = controller.shoot_step, []

    def shoot_step(*args: Any, **kwargs: Any) -> Any:
        shots.append(1)
        if len(shots) == 3:
            signal.raise_signal(signal.SIGINT)
            signal.raise_signal(signal.SIGINT)
        return real_shoot(*args, **kwargs)

    monkeypatch.setattr(controller, "shoot_step", shoot_step)
    _ctrl_c_as(monkeypatch, cli_session, "_after_stop")
    r, said, out = _run(tmp_path)
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    lights = said.index("Emergency stop (second Ctrl-C): lights were switched off.")
    late = said.index("Ctrl-C after the capture had ended")
    assert lights < late, said
    assert "teardown has run (what it did is said above)" in said, said
    assert f"Continue with: rti-rig run --resume {out}" in said[late:], said
    assert r.exit_code == 130, said
