"""A camera whose clock is changed mid-session by less than the time since the run's first
image, through `rti-rig run` on the shipped folder-watch example (its dome firmware emulated on
a pty, its camera a thread that saves a DNG stamped with the camera's clock into the watched
folder for each shutter pulse the board saw).

The pulse's own file is then out of step and rightly not taken, but every such stop called it
"a late file of an earlier pulse?": also a file shot after the pulse (a clock set forward: no
late file is shot after its pulse), and one whose capture time lands on an earlier pulse of
the run, where a late file and a clock set back are both possible and the capture times
cannot tell which.

Each stop's way out ("If the clock was set forward/back, delete <clock file> and resume") is
followed as written, the camera's clock left as its owner set it: the resume takes the lights
left (the advice had been reasoned, never run).
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
from conftest import folder_watch_config, journal, tethered_run
from dng_spec_writer import dng, mosaic_from_rgb

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: the camera clock's reading at the board's time 0
CAMERA_EPOCH = datetime.datetime(2026, 11, 30, 9, 0, 0)


class ClockChangingCamera(threading.Thread):
    """A camera fired by the board's shutter line: each pulse's DNG is saved into ``folder``,
    stamped with the camera clock at the pulse (in whole seconds, as EXIF keeps them) plus
    ``offset_s``; before its third shot its owner moves the clock by ``change(pulse times)``
    seconds (None: the clock is left as it is). Its file counter goes on from the files
    already in ``folder``."""

    def __init__(
        self,
        firmware: Any,
        folder: Path,
        change: Callable[[list[float]], float] | None,
        offset_s: float = 0.0,
    ) -> None:
        super().__init__(daemon=True)
        self.firmware, self.folder, self.change = firmware, folder, change
        self.offset_s = offset_s
        self.saved = 0
        self.numbered = len(list(folder.iterdir()))
        self.stop = threading.Event()

    def run(self) -> None:
        mosaic = mosaic_from_rgb(np.full((32, 48, 3), 0.3), "RGGB", (0,) * 4, 4095)
        while not self.stop.is_set():
            pulses = [e.time_s for e in list(self.firmware.history) if e.what == "shutter"]
            while self.saved < len(pulses):
                if self.saved == 2 and self.change is not None:
                    self.offset_s += self.change(pulses)
                stamp = CAMERA_EPOCH + datetime.timedelta(
                    seconds=pulses[self.saved] + self.offset_s
                )
                self.saved += 1
                data = dng(
                    mosaic, "RGGB", (0,) * 4, 4095, date_time=stamp.strftime("%Y:%m:%d %H:%M:%S")
                )
                name = f"IMG_{self.numbered + self.saved:04d}.DNG"
                (self.folder / name).write_bytes(data)
            self.stop.wait(0.02)


def _run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, change: Any
) -> tuple[Any, ClockChangingCamera]:
    """The run of 4 lights, its camera's clock moved by ``change`` before its third shot: what
    it left (:class:`conftest.TetheredRun`) and the camera (its clock as moved)."""
    tether = tmp_path / "tether"
    tether.mkdir()
    # pulses at least 1.5 s apart, so that a capture time on pulse 1's whole second cannot
    # also fit pulse 3's (EXIF keeps whole seconds; at the shipped 0.2 s settle the pulses
    # of a fast run came under a second apart, and the set-back file was taken as pulse 3's)
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0, settle_s=1.5)
    out = tmp_path / "s"
    cameras: list[ClockChangingCamera] = []

    def camera(firmware: Any) -> ClockChangingCamera:
        cameras.append(ClockChangingCamera(firmware, tether, change))
        return cameras[-1]

    return tethered_run(monkeypatch, cfg, tether, [], out, camera=camera, lights=4), cameras[0]


def _follow_the_way_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, said: str, stopped: ClockChangingCamera
) -> Any:
    """Do what the stop said, as written ("If the clock was set forward/back, delete FILE and
    resume"), the camera's clock left where its owner moved it (``stopped``'s offset: the
    boards of both runs date their pulses by one monotonic clock): the resume's outcome."""
    found = re.search(r"If the clock was set (?:forward|back), delete (\S+) and resume", said)
    assert found, said
    clock_file = Path(found.group(1))
    assert clock_file == tmp_path / "s" / "raw" / ".folder_watch_clock.json", clock_file
    clock_file.unlink()
    tether = tmp_path / "tether"
    cfg = tmp_path / "example_dome_48_folder_watch.toml"
    return tethered_run(
        monkeypatch,
        cfg,
        tether,
        [],
        tmp_path / "s",
        camera=lambda firmware: ClockChangingCamera(firmware, tether, None, stopped.offset_s),
        resume=True,
    )


def _resumes_without_the_stopped_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, said: str, stopped: ClockChangingCamera
) -> None:
    """The way out followed (:func:`_follow_the_way_out`) completes the session, lights off,
    its 4 lights shot by the resumed lights' own files, never the set-aside IMG_0003.DNG."""
    resumed = _follow_the_way_out(tmp_path, monkeypatch, said, stopped)
    assert resumed.result.exit_code == 0, resumed.said
    assert not resumed.lit_at_end, resumed.said
    assert (tmp_path / "s" / "lights.lp").read_text().split()[0] == "4"
    taken = [list(step["originals"].values()) for step in journal(tmp_path / "s")]
    assert taken == [["IMG_0001.DNG"], ["IMG_0002.DNG"], ["IMG_0004.DNG"], ["IMG_0005.DNG"]]


def test_a_clock_set_forward_mid_run_is_said_as_such_not_as_a_late_file(tmp_path, monkeypatch):
    (r, said, lit), stopped = _run(tmp_path, monkeypatch, lambda pulses: 40.0)
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

    _resumes_without_the_stopped_file(tmp_path, monkeypatch, said, stopped)


def test_a_clock_set_back_onto_an_earlier_pulse_is_said_as_either(tmp_path, monkeypatch):
    # set back by exactly the time since the first pulse: its capture time lands on pulse 1's
    (r, said, lit), stopped = _run(tmp_path, monkeypatch, lambda pulses: -(pulses[2] - pulses[0]))
    assert r.exit_code == 2, said
    assert "Traceback" not in said and not lit, said
    assert "which fits this run's pulse 1" in said, said
    assert "either a late file of an earlier pulse or the camera's clock set back by about" in (
        said
    ), said
    assert "the capture times cannot tell which" in said, said

    _resumes_without_the_stopped_file(tmp_path, monkeypatch, said, stopped)
