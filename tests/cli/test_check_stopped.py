"""`rti-rig check` stopped by SIGTERM or Ctrl-C goes through its teardown and says what it
knows about the lights. Without a handler SIGTERM killed the process at once: the emulated
RTI v1.0 sketch was left with an LED lit and nothing was printed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
#: the CLI with the dome's third ``light`` holding (its LED lit) until a signal ends it
STALL_AT_THIRD_LED = """
import sys, time
from rti_rig.runtime.dome_policy import DomePolicy
real = DomePolicy.light
def light(self, index, intensity=1.0):
    real(self, index, intensity)
    if index == 2:
        print("LIT 2", file=sys.stderr, flush=True)
        end = time.monotonic() + 60.0
        while time.monotonic() < end:
            time.sleep(0.05)
DomePolicy.light = light
from rti_rig.cli import app
app(sys.argv[1:], prog_name="rti-rig")
"""


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize(
    ("sig", "code", "name"), [(signal.SIGTERM, 143, "SIGTERM"), (signal.SIGINT, 130, "Ctrl-C")]
)
def test_a_stopped_check_switches_the_dome_off_and_says_so(sig, code, name) -> None:
    cfg = REPO / "rig_configs" / "emulated_nab_rti_v1.toml"
    proc = subprocess.Popen(
        [sys.executable, "-c", STALL_AT_THIRD_LED, "check", str(cfg)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "COLUMNS": "200"},
    )
    assert proc.stderr is not None
    for line in proc.stderr:  # the third LED is lit and its firmware has acknowledged it
        if line.startswith("LIT 2"):
            break
    else:
        raise AssertionError(f"the walk never reached the third LED: {proc.communicate()}")
    proc.send_signal(sig)
    out, errs = proc.communicate(timeout=120)
    said = " ".join((out + errs).split())
    assert proc.returncode == code, said
    assert "Traceback" not in said
    assert f"Check stopped ({name})" in said, said
    # what the teardown established (the sketch acknowledges its all-off), never "never
    # reached" for a dome whose port was open
    assert "never reached" not in said
    assert "all-off sent and acknowledged" in said, said
