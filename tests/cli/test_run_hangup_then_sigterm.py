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
from conftest import CONFIGS, ended_on_exit, eventually

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
    assert "SIGTERM" not in words, words
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == "emergency-stop", runner
    assert runner["error"] == "emergency stop: SIGHUP", runner
    kept = sorted(p.name for p in out.glob("image_*.jpg"))
    journal = [json.loads(line) for line in (out / "journal.jsonl").read_text().splitlines()]
    assert len(journal) == len(kept) >= 2, (journal, kept)
    listed = (out / "lights.lp").read_text()
    assert all(name in listed for name in kept), listed
