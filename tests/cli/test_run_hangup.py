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
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, manifest
from conftest import said as unwrapped
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.deferred_signals import signal_handlers

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or not hasattr(signal, "SIGHUP"), reason="signals tested on Linux"
)


@pytest.fixture
def hangup_guarded() -> Iterator[None]:
    """A SIGHUP nothing in rti-rig answers fails the test (its default would end pytest)."""

    def unhandled(signum: int, frame: Any) -> None:
        raise AssertionError("SIGHUP was not handled by rti-rig (the default ends the process)")

    with signal_handlers({signal.SIGHUP: unhandled}):
        yield
    # put back by the block: the command left it as it found it
    assert signal.getsignal(signal.SIGHUP) is not unhandled


def _hangup_at_third_led(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """SIGHUP raised in the run's process once its third LED is lit (the firmware has
    acknowledged it); the emulated firmwares built from here on, to read their truth from."""
    import rti_rig.simulator.dome_firmware as dome_firmware
    from rti_rig.runtime.dome_policy import DomePolicy

    firmwares: list[Any] = []
    real_firmware_for = dome_firmware.firmware_for

    def firmware_for(*args: Any, **kwargs: Any) -> Any:
        firmware = real_firmware_for(*args, **kwargs)
        firmwares.append(firmware)
        return firmware

    real_light = DomePolicy.light
    raised: list[int] = []

    def light(self: Any, index: int, intensity: float = 1.0) -> None:
        real_light(self, index, intensity)
        if len(firmwares) == 1 and not raised and firmwares[0].lit is not None:
            lit_steps.append(index)
            if len(lit_steps) == 3:
                raised.append(index)
                signal.raise_signal(signal.SIGHUP)

    lit_steps: list[int] = []
    monkeypatch.setattr(dome_firmware, "firmware_for", firmware_for)
    monkeypatch.setattr(DomePolicy, "light", light)
    return firmwares


def test_a_hangup_mid_run_switches_the_dome_off_records_the_end_and_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, hangup_guarded: None
) -> None:
    out = tmp_path / "s"
    runner = CliRunner()
    with monkeypatch.context() as patched:
        firmwares = _hangup_at_third_led(patched)
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
        _hangup_at_third_led(patched)
        argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
        r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
        assert signal.getsignal(signal.SIGHUP) == signal.SIG_IGN
    assert r.exit_code == 0, unwrapped(r)
    assert manifest(out)["runner"]["finish_reason"] == "completed"
