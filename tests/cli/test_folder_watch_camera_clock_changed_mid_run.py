"""A camera whose clock is changed mid-session by less than the time since the run's first
image, through `rti-rig run` on the shipped folder-watch example (its dome firmware emulated on
a pty, its camera a thread that saves a DNG stamped with the camera's clock into the watched
folder for each shutter pulse the board saw).

The pulse's own file is then out of step and rightly not taken, but every such stop called it
"a late file of an earlier pulse?": also a file shot after the pulse (a clock set forward: no
late file is shot after its pulse), and one whose capture time lands on an earlier pulse of
the run, where a late file and a clock set back are both possible and the capture times
cannot tell which.
"""

from __future__ import annotations

import datetime
import re
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import folder_watch_config, shipped_dome_on_pty
from dng_spec_writer import dng, mosaic_from_rgb
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: the camera clock's reading at the board's time 0
CAMERA_EPOCH = datetime.datetime(2026, 11, 30, 9, 0, 0)


class ClockChangingCamera(threading.Thread):
    """A camera fired by the board's shutter line: each pulse's DNG is saved into ``folder``,
    stamped with the camera clock at the pulse (in whole seconds, as EXIF keeps them); before
    its third shot its owner moves the clock by ``change(pulse times)`` seconds."""

    def __init__(self, firmware: Any, folder: Path, change: Callable[[list[float]], float]) -> None:
        super().__init__(daemon=True)
        self.firmware, self.folder, self.change = firmware, folder, change
        self.offset_s = 0.0
        self.saved = 0
        self.stop = threading.Event()

    def run(self) -> None:
        mosaic = mosaic_from_rgb(np.full((32, 48, 3), 0.3), "RGGB", (0,) * 4, 4095)
        while not self.stop.is_set():
            pulses = [e.time_s for e in list(self.firmware.history) if e.what == "shutter"]
            while self.saved < len(pulses):
                if self.saved == 2:
                    self.offset_s += self.change(pulses)
                stamp = CAMERA_EPOCH + datetime.timedelta(
                    seconds=pulses[self.saved] + self.offset_s
                )
                self.saved += 1
                data = dng(
                    mosaic, "RGGB", (0,) * 4, 4095, date_time=stamp.strftime("%Y:%m:%d %H:%M:%S")
                )
                (self.folder / f"IMG_{self.saved:04d}.DNG").write_bytes(data)
            self.stop.wait(0.02)


def _run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, change: Any) -> tuple[Any, str, Any]:
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0)
    # pulses at least 1.5 s apart, so that a capture time on pulse 1's whole second cannot
    # also fit pulse 3's (EXIF keeps whole seconds; at the shipped 0.2 s settle the pulses
    # of a fast run came under a second apart, and the set-back file was taken as pulse 3's)
    text = cfg.read_text(encoding="utf-8")
    assert "settle_s = 0.2\n" in text
    cfg.write_text(text.replace("settle_s = 0.2\n", "settle_s = 1.5\n"), encoding="utf-8")
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        camera = ClockChangingCamera(firmware, tether, change)
        camera.start()
        try:
            args = ["run", str(cfg), "--out", str(out), "--lights", "4", "--no-verdict"]
            r = CliRunner().invoke(app, args, terminal_width=400)
        finally:
            camera.stop.set()
            camera.join(5.0)
        lit = firmware.lit_indices()
    return r, " ".join(r.output.split()), lit


def test_a_clock_set_forward_mid_run_is_said_as_such_not_as_a_late_file(tmp_path, monkeypatch):
    r, said, lit = _run(tmp_path, monkeypatch, lambda pulses: 40.0)
    assert r.exit_code == 2, said
    assert "Traceback" not in said and not lit, said
    assert "late file of an earlier pulse?" not in said, said
    assert "so it is no late file of an earlier pulse" in said, said
    # 40 s, read from capture times EXIF keeps in whole seconds: 39, 40 or 41 by where the
    # pulses fall within their seconds
    assert re.search(r"IMG_0003\.DNG was shot (39|40|41) s after this pulse", said), said
    assert re.search(r"the camera's clock was set forward by about (39|40|41) s", said), said
    clock_file = tmp_path / "s" / "raw" / ".folder_watch_clock.json"
    assert f"delete {clock_file} and resume" in said, said


def test_a_clock_set_back_onto_an_earlier_pulse_is_said_as_either(tmp_path, monkeypatch):
    # set back by exactly the time since the first pulse: its capture time lands on pulse 1's
    r, said, lit = _run(tmp_path, monkeypatch, lambda pulses: -(pulses[2] - pulses[0]))
    assert r.exit_code == 2, said
    assert "Traceback" not in said and not lit, said
    assert "which fits this run's pulse 1" in said, said
    assert "either a late file of an earlier pulse or the camera's clock set back by about" in (
        said
    ), said
    assert "the capture times cannot tell which" in said, said
