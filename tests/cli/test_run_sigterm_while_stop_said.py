"""A SIGTERM while ``run`` says how its capture ended (a Ctrl-C stop, a failed capture) ends
the run with exit 143, as every other SIGTERM does, once what was being said is out.

The SIGTERM there was recorded (the run's late handler holds it so the report is not cut)
but the run then exited with the stop's 130, or the error's 2: a service manager or
``timeout`` that sent SIGTERM was told the run had ended on a Ctrl-C or an error of its own.
The SIGTERM is raised in the run's own process at the point under test (no timing).
"""

from __future__ import annotations

import signal
import sys
import threading
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.cli.session as cli_session
import rti_rig.runtime.controller as controller
from rti_rig.cli import app
from rti_rig.core.errors import CaptureError
from rti_rig.runtime.session import SessionFolder


def _sigterm_as_the_end_is_said(monkeypatch: pytest.MonkeyPatch, wording: str) -> list[int]:
    """SIGTERM raised once, as the run calls ``wording`` (one of its functions that word how
    the session ended: what a stopped session left on disk, or a cancelled one's time)."""
    sent: list[int] = []
    real = getattr(cli_session, wording)

    def worded(*args: Any, **kwargs: Any) -> str:
        if not sent:
            sent.append(signal.SIGTERM)
            signal.raise_signal(signal.SIGTERM)
        return real(*args, **kwargs)

    monkeypatch.setattr(cli_session, wording, worded)
    return sent


def _stopped_by_ctrl_c(monkeypatch: pytest.MonkeyPatch, times: int) -> list[bool]:
    """Ctrl-C ``times`` times (twice: stop at once) once the second image is committed.

    No race with the 4 images left: the signals are raised in the main thread, inside the
    commit's hold, which delivers them as it ends, before the next image. Returns whether the
    commit ran in the main thread (asserted: off it, the handler would run whenever the main
    thread next checks, possibly after the capture, and the test would race as a subprocess's
    did, see 1fcd3d88)."""
    real = SessionFolder.write_step
    in_main: list[bool] = []

    def write_step(self, index, *args, **kwargs):  # type: ignore[no-untyped-def]
        record = real(self, index, *args, **kwargs)
        if index == 1:
            in_main.append(threading.current_thread() is threading.main_thread())
            for _ in range(times):
                signal.raise_signal(signal.SIGINT)
        return record

    monkeypatch.setattr(SessionFolder, "write_step", write_step)
    return in_main


def _camera_fails_at_third(monkeypatch: pytest.MonkeyPatch) -> None:
    real, shots = controller.shoot_step, []

    def shoot_step(*args, **kwargs):  # type: ignore[no-untyped-def]
        shots.append(1)
        if len(shots) == 3:
            raise CaptureError("camera", "no frame came (the cable was pulled)")
        return real(*args, **kwargs)

    monkeypatch.setattr(controller, "shoot_step", shoot_step)


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize(
    ("ending", "wording", "said_first"),
    [
        ("two ctrl-c", "_after_stop", "Emergency stop (second Ctrl-C)"),
        ("one ctrl-c", "_time_line", "Session cancelled; the images captured so far are kept"),
        ("error", "_after_stop", "no frame came (the cable was pulled)"),
    ],
)
def test_a_sigterm_while_the_end_of_the_capture_is_said_exits_143(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, ending: str, wording: str, said_first: str
) -> None:
    in_main = [True]
    if ending == "error":
        _camera_fails_at_third(monkeypatch)
    else:
        in_main = _stopped_by_ctrl_c(monkeypatch, 2 if ending == "two ctrl-c" else 1)
    sent = _sigterm_as_the_end_is_said(monkeypatch, wording)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    said = " ".join(r.output.split())
    assert sent == [signal.SIGTERM], said
    assert in_main == [True], said  # raised where the commit's hold delivers them at once
    assert "Traceback" not in said, said
    assert said_first in said, said  # what the run was saying is out
    assert "2 image(s)" in said and "Continue with: rti-rig run --resume" in said, said
    assert "SIGTERM while the run's end was being said" in said, said
    assert r.exit_code == 143, said
