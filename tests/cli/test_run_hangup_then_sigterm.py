"""``run`` on the shipped simulated dome, hung up (SIGHUP: the terminal closed) and then sent
a SIGTERM (a supervisor's ``kill``) once its second image is on disk: the hang-up decided the
stop, and the run says, records and exits it as SIGHUP (129), the images kept listed.

The SIGTERM that follows finds the stop under way; it is not the one that stopped the run,
so it is not named as if it were (nor is the hang-up named SIGTERM). The signals are sent
once the image's file is there (waited on, bounded), not after a sleep.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, ended_on_exit, eventually, manifest, said, sighup_at_lit_led
from conftest import signal_as_the_teardown_switches_off as signal_in_teardown
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.deferred_signals import signal_handlers

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or not hasattr(signal, "SIGHUP"), reason="signals tested on Linux"
)


def test_a_hangup_then_a_sigterm_is_said_recorded_and_exited_as_the_hangup(
    tmp_path: Path,
) -> None:
    out = tmp_path / "s"
    # every light of the dome (48): sent at the second image, the signals must find the capture
    # under way; with 6 lights a test process held off the CPU for the 4 images left had sent
    # them after the capture, where the second stop ends the process as the default does
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out)]
    process = subprocess.Popen(
        [sys.executable, "-m", "rti_rig", *argv, "--no-verdict"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "COLUMNS": "400"},
        text=True,
    )
    with ended_on_exit(process):
        assert eventually(lambda: (out / "image_002.jpg").exists(), timeout_s=300)
        process.send_signal(signal.SIGHUP)
        process.send_signal(signal.SIGTERM)
        _, stderr = process.communicate(timeout=300)
    words = " ".join(stderr.split())
    assert process.returncode == 129, words  # 128 + SIGHUP
    assert "Traceback" not in words, words
    assert "Emergency stop (SIGHUP): lights were switched off." in words, words
    # said once, as a signal that came during the stop, never as the stop's name
    also = "SIGTERM also arrived: the stop (SIGHUP) is already under way"
    assert words.count(also) == 1 and words.count("SIGTERM") == 1, words
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == "emergency-stop", runner
    assert runner["error"] == "emergency stop: SIGHUP", runner
    kept = sorted(p.name for p in out.glob("image_*.jpg"))
    journal = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    assert len(journal) == len(kept) >= 2, (journal, kept)
    listed = (out / "lights.lp").read_text()
    assert all(name in listed for name in kept), listed


class SigtermUnhandled(Exception):
    """A SIGTERM nothing in rti-rig answered (the default would end pytest)."""


def test_a_sigterm_during_a_hangups_teardown_is_said_and_the_teardown_finishes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, hangup_guarded: None
) -> None:
    """The SIGTERM is raised in the run's own process as the hang-up's teardown switches the
    dome off (no timing): it had raised a second emergency stop as the teardown's hold ended,
    which replaced the hang-up's (said "Emergency stop (SIGTERM)", exit 143, while the manifest
    recorded SIGHUP)."""
    out = tmp_path / "s"

    def unhandled(signum: int, frame: object) -> None:
        raise SigtermUnhandled("SIGTERM was not handled by rti-rig")

    with monkeypatch.context() as patched, signal_handlers({signal.SIGTERM: unhandled}):
        firmwares = sighup_at_lit_led(patched, 3)
        # held by the teardown, delivered after it
        sent = signal_in_teardown(patched, signal.SIGTERM)
        argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
        r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    words = said(r)
    assert sent == [True]
    assert r.exit_code == 129, words  # the hang-up's stop, not the SIGTERM's (143)
    assert "Traceback" not in words and not isinstance(r.exception, SigtermUnhandled), words
    assert "SIGTERM also arrived: the stop (SIGHUP) is already under way" in words, words
    assert words.count("SIGTERM") == 1, words
    assert "Emergency stop (SIGHUP): all-off sent and acknowledged by the dome" in words, words
    (firmware,) = firmwares
    assert firmware.lit is None and firmware.history[-1].what == "off"
    runner = manifest(out)["runner"]
    assert runner["finish_reason"] == "emergency-stop", runner
    assert runner["error"] == "emergency stop: SIGHUP", runner
