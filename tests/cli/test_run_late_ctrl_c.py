"""A Ctrl-C held by a dome session's teardown (its all-off) is not answered "Stopping after
this image": the capture is over, and there is no image left to stop after.

The controller holds Ctrl-C while the rig goes safe and delivers it once that is done; the
run's handler then said "Stopping after this image (Ctrl-C again to stop at once)…" after
the last image (the arm's case: tests/cli/test_run_arm_park_stopped.py)."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner, Result

import rti_rig.runtime.controller as controller
from rti_rig.cli import app
from rti_rig.core.errors import CaptureError
from rti_rig.runtime.lighting import DomeLighting


def _ctrl_c_in_the_teardown(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """A Ctrl-C (SIGINT) raised as the dome's teardown makes the rig safe, where the
    controller holds it until the teardown is done: the list records each one raised."""
    raised: list[int] = []
    real_safe = DomeLighting.safe

    def safe(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        raised.append(signal.SIGINT)
        signal.raise_signal(signal.SIGINT)  # held by the teardown, delivered once it is done
        return real_safe(self, *args, **kwargs)

    monkeypatch.setattr(DomeLighting, "safe", safe)
    return raised


def _run_six_lights(tmp_path: Path) -> tuple[Result, str, Path]:
    """``rti-rig run`` of the shipped simulated dome, 6 lights, no verdict: the result, its
    words (one line) and the session folder."""
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    return r, " ".join(r.output.split()), out


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_during_a_dome_s_teardown_is_not_said_to_stop_after_an_image(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    raised = _ctrl_c_in_the_teardown(monkeypatch)
    r, said, _out = _run_six_lights(tmp_path)
    assert raised == [signal.SIGINT], said
    assert "Traceback" not in said, said
    assert "Stopping after this image" not in said, said
    assert "Ctrl-C after the capture had ended: there was nothing left to stop" in said, said
    assert "6 image(s) in the session" in said, said
    assert r.exit_code == 0, said


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_in_the_teardown_of_a_failed_capture_does_not_say_every_image_is_in(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The camera fails at image 3 of 6; a Ctrl-C in the teardown had been answered "no image
    was left to stop after", read as every image in, above "2 image(s) kept … Continue with:
    rti-rig run --resume"."""
    real_shoot, shots = controller.shoot_step, []

    def shoot_step(*args, **kwargs):  # type: ignore[no-untyped-def]
        shots.append(1)
        if len(shots) == 3:
            raise CaptureError("camera", "no frame came (the cable was pulled)")
        return real_shoot(*args, **kwargs)

    monkeypatch.setattr(controller, "shoot_step", shoot_step)
    raised = _ctrl_c_in_the_teardown(monkeypatch)
    r, said, out = _run_six_lights(tmp_path)
    assert raised == [signal.SIGINT] and len(shots) == 3, said
    assert "Traceback" not in said, said
    assert "no image was left" not in said, said
    assert "Ctrl-C after the capture had ended: there was nothing left to stop" in said, said
    assert f"2 image(s) kept in {out}, listed in lights.lp. Continue with: rti-rig run" in said
    assert "camera: no frame came" in said and r.exit_code == 2, said  # an error, not a stop
