"""``runner.state`` of ``manifest.json`` says how the last run ended, the same for one stop.

A run stopped by SIGTERM (or Ctrl-C) mid-capture had recorded ``state: finished``, as a
complete session does, while the same stop a moment later (cutting the end record short:
tests/cli/test_run_cut_end_recorded.py) recorded ``stopped``. Now a recorded end reads
``finished`` only for a run that completed its plan, ``stopped`` for any other, through the
CLI on the shipped config; the resume that completes the session reads ``finished``.
"""

from __future__ import annotations

import json
import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.runtime.session import SessionFolder

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")


def _signal_after_step(monkeypatch: pytest.MonkeyPatch, signum: int, index: int) -> None:
    """A real ``signum`` raised in the run's own process once step ``index`` is written (a
    known point of the capture, not a race against the clock)."""
    real = SessionFolder.write_step

    def write_step(self: SessionFolder, i: int, *args: Any, **kwargs: Any) -> Any:
        record = real(self, i, *args, **kwargs)
        if i == index:
            signal.raise_signal(signum)
        return record

    monkeypatch.setattr(SessionFolder, "write_step", write_step)


def _runner(out: Path) -> dict[str, Any]:
    return json.loads((out / "manifest.json").read_text())["runner"]


@pytest.mark.parametrize(
    ("signum", "code", "reason"),
    [(signal.SIGTERM, 143, "emergency-stop"), (signal.SIGINT, 130, "cancelled")],
)
def test_a_run_stopped_mid_capture_reads_stopped_and_its_completion_finished(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, signum: int, code: int, reason: str
) -> None:
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "6"]
    with monkeypatch.context() as patched:
        _signal_after_step(patched, signum, 1)
        r = CliRunner().invoke(app, [*argv, "--no-verdict"])
    assert r.exit_code == code, said(r)
    runner = _runner(out)
    assert runner["finish_reason"] == reason and runner["state"] == "stopped", runner
    assert runner["steps_done"] < runner["steps_planned"] == 6, runner
    assert "end_cut" not in runner  # the end was recorded whole, by the teardown

    r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, said(r)
    runner = _runner(out)
    assert runner["finish_reason"] == "completed" and runner["state"] == "finished", runner
