"""A second Ctrl-C that lands once a run stopped by a first one has ended its capture (held by
the teardown as it switches the dome off, delivered once that is done) is said in one line;
the stop stays the first Ctrl-C's, "Session cancelled", as the manifest records it.

Found by a dome audit (the Nab dome's emulator, 12 lights): after "Stopping after this image",
a second Ctrl-C at the end of an image said "Emergency stop (second Ctrl-C)" while
manifest.json recorded ``finish_reason: cancelled`` (4 times in 12). The manifest was right:
the capture had already ended as the first Ctrl-C asked, after its image, and the teardown ran
as a cancel's, not an emergency's (``safe(emergency=False)``); there was nothing left to stop
at once. A second Ctrl-C during the capture still stops it at once
(tests/cli/test_run_ctrl_c_after_last_image.py). Through the console entry in a child
process; no timing: the first Ctrl-C is raised as image 2 is committed, the second as the
teardown sends its all-off.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO

_CHILD = r"""
import os, signal, sys
from rti_rig.runtime.lighting import DomeLighting
from rti_rig.runtime.session import SessionFolder

real_write, real_safe, teardowns = SessionFolder.write_step, DomeLighting.safe, []

def write_step(self, index, *args, **kwargs):
    record = real_write(self, index, *args, **kwargs)
    if index == int(os.environ.get("FIRST_AT", "1")):
        signal.raise_signal(signal.SIGINT)  # the first Ctrl-C: stop after this image
    return record

def safe(self, *args, **kwargs):
    teardowns.append(kwargs.get("emergency", args[0] if args else False))
    if len(teardowns) == 1:
        signal.raise_signal(signal.SIGINT)  # the second, as the teardown switches off
    return real_safe(self, *args, **kwargs)

SessionFolder.write_step = write_step
DomeLighting.safe = safe
sys.argv = ["rti-rig", *sys.argv[1:]]
from rti_rig.launch import main
try:
    main()
finally:
    print(f"teardowns: {teardowns}", file=sys.stderr)
"""


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_second_ctrl_c_in_a_cancelled_run_s_teardown_keeps_the_cancel(tmp_path: Path) -> None:
    out = tmp_path / "s"
    config = CONFIGS / "emulated_nab_rti_v1.toml"
    argv = ["run", str(config), "--lights", "4", "--out", str(out), "--no-verdict"]
    result = _two_ctrl_c(argv)
    said = " ".join(result.stderr.decode("utf-8", "replace").split())
    assert "teardowns: [False]" in said, said  # one teardown, a cancel's: the second came in it
    run = json.loads((out / "manifest.json").read_text())["runs"][-1]
    assert run["finish_reason"] == "cancelled", run
    assert "Stopping after this image" in said, said
    assert "Emergency stop" not in said and "Traceback" not in said, said
    assert said.count("Ctrl-C after the capture had ended: there was nothing left to stop") == 1
    assert "Session cancelled; the images captured so far are kept." in said, said
    assert "All-off sent and acknowledged by the dome: lights are off." in said, said
    assert f"Continue with: rti-rig run --resume {out}" in said, said
    assert result.returncode == 130, said


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_two_ctrl_c_as_a_preview_ends_stop_it_once_it_is_taken(tmp_path: Path) -> None:
    """The preview's one image is in when the first Ctrl-C comes, the second as the teardown
    switches off: the preview is complete (its manifest: completed) and the run says so as
    for a late SIGTERM, exit 130. It had ended with exit 0 and no word of the stop the user
    asked for twice (before the second Ctrl-C stopped nothing: "Emergency stop", 130)."""
    out = tmp_path / "p"
    argv = ["preview", str(CONFIGS / "simulated_dome.toml"), "--out", str(out)]
    result = _two_ctrl_c(argv, first_at=0)
    said = " ".join(result.stderr.decode("utf-8", "replace").split())
    assert "teardowns: [False]" in said, said
    run = json.loads((out / "manifest.json").read_text())["runs"][-1]
    assert run["finish_reason"] == "completed", run
    assert "Emergency stop" not in said and "Traceback" not in said, said
    assert said.count("Ctrl-C after the capture had ended: there was nothing left to stop") == 1
    assert f"Stopped (Ctrl-C) once the preview was taken: it is complete in {out}" in said, said
    assert "rti-rig plan" in result.stdout.decode("utf-8", "replace"), result.stdout
    assert result.returncode == 130, said


def _two_ctrl_c(argv: list[str], first_at: int = 1) -> subprocess.CompletedProcess[bytes]:
    """``rti-rig ARGV`` in a child whose first Ctrl-C comes as image ``first_at`` (from 0) is
    committed and whose second comes as the teardown switches the lights off."""
    return subprocess.run(
        [sys.executable, "-c", _CHILD, *argv],
        capture_output=True,
        env={
            **os.environ,
            "PYTHONPATH": str(REPO),
            "COLUMNS": "300",
            "FIRST_AT": str(first_at),
        },
        timeout=600,
    )


#: the second Ctrl-C once the capture has returned, as the progress bar closes (after the
#: teardown, before the summary's ignore is set)
_AS_THE_BAR_CLOSES = r"""
import os, signal, sys
import rich.progress
from rti_rig.runtime.session import SessionFolder

real_write, real_exit = SessionFolder.write_step, rich.progress.Progress.__exit__

def write_step(self, index, *args, **kwargs):
    record = real_write(self, index, *args, **kwargs)
    if index == 3:
        signal.raise_signal(signal.SIGINT)  # the first Ctrl-C, as the last image is in
    return record

def bar_closes(self, *args):
    signal.raise_signal(signal.SIGINT)  # the second, the capture returned
    return real_exit(self, *args)

SessionFolder.write_step = write_step
rich.progress.Progress.__exit__ = bar_closes
sys.argv = ["rti-rig", *sys.argv[1:]]
from rti_rig.launch import main
main()
"""


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_second_ctrl_c_just_after_the_teardown_stops_the_run_as_one_in_it(
    tmp_path: Path,
) -> None:
    """Landing once the capture has returned (its progress bar closing) rather than in the
    teardown, the second Ctrl-C of a complete session had been said and then forgotten: the
    run went on to its verdict and exited 0, where one a moment earlier exits 130 before it."""
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--lights", "4", "--out", str(out)]
    result = subprocess.run(
        [sys.executable, "-c", _AS_THE_BAR_CLOSES, *argv],
        capture_output=True,
        env={**os.environ, "PYTHONPATH": str(REPO), "COLUMNS": "300"},
        timeout=600,
    )
    said = " ".join(result.stderr.decode("utf-8", "replace").split())
    run = json.loads((out / "manifest.json").read_text())["runs"][-1]
    assert run["finish_reason"] == "completed", run
    assert "Every image is in" in said and "Emergency stop" not in said, said
    assert said.count("Ctrl-C after the capture had ended: there was nothing left to stop") == 1
    assert "Stopped (Ctrl-C) once the session had ended: it is complete" in said, said
    assert "verdict" not in result.stdout.decode("utf-8", "replace").lower(), result.stdout
    assert result.returncode == 130, said
