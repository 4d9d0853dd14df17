"""A hang-up (SIGHUP: the terminal or the ssh connection closing) during ``run`` is a stop as
SIGTERM's: the lit LED is switched off, the run's end recorded naming SIGHUP, exit 129, and
``--resume`` completes the session.

Before, SIGHUP had no handler: the process died at once (exit 129) with the dome's LED lit, no
teardown and the manifest's ``finish_reason`` null. The SIGHUP is raised in the run's own
process once the third LED is lit and acknowledged (no timing); a handler set by the test
beforehand turns an unhandled SIGHUP into a failure rather than the end of pytest.
"""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, manifest, sighup_at_lit_led
from conftest import said as unwrapped
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.deferred_signals import signal_handlers

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or not hasattr(signal, "SIGHUP"), reason="signals tested on Linux"
)


def test_a_hangup_mid_run_switches_the_dome_off_records_the_end_and_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, hangup_guarded: None
) -> None:
    out = tmp_path / "s"
    runner = CliRunner()
    with monkeypatch.context() as patched:
        firmwares = sighup_at_lit_led(patched, 3)
        argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
        r = runner.invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    said = unwrapped(r)
    assert r.exit_code == 129, said  # 128 + SIGHUP, as the shell reports a hang-up
    assert "Traceback" not in said and "SIGTERM" not in said, said
    assert "SIGHUP" in said, said
    # the emulator's truth: the LED lit when the hang-up came was switched off after it
    (firmware,) = firmwares
    assert firmware.lit is None
    events = [e.what for e in firmware.history]
    assert "lit" in events and events[-1] == "off", events
    runner_record = manifest(out)["runner"]
    assert runner_record["finish_reason"] == "emergency-stop", runner_record
    assert runner_record["state"] == "stopped", runner_record
    assert "SIGHUP" in str(runner_record["error"]), runner_record
    assert runner_record["steps_done_this_run"] == 2, runner_record

    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"], terminal_width=400)
    assert r.exit_code == 0, unwrapped(r)
    resumed = manifest(out)["runner"]
    assert resumed["finish_reason"] == "completed", resumed
    assert len(list(out.glob("image_*.jpg"))) == 6


def test_a_run_started_with_the_hangup_ignored_goes_on_to_its_end(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``nohup rti-rig run …``: SIGHUP ignored as the run begins is left ignored (the session
    is meant to outlive its terminal); the hang-up stops nothing and the session completes."""
    out = tmp_path / "s"
    with monkeypatch.context() as patched, signal_handlers({signal.SIGHUP: signal.SIG_IGN}):
        sighup_at_lit_led(patched, 3)
        argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
        r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
        assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
    assert r.exit_code == 0, unwrapped(r)
    assert manifest(out)["runner"]["finish_reason"] == "completed"
