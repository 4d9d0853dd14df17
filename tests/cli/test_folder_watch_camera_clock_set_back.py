"""A camera whose clock is set back mid-session (a time-zone or daylight-saving change made on
the body), through `rti-rig run` on the shipped folder-watch example (its dome firmware
emulated on a pty, its camera a thread that saves a DNG stamped with the camera's clock into
the watched folder for each shutter pulse the board saw), then the way out the stop gives.

The pulse's own picture then carries a capture time before the run's first image. It is
rightly not taken (the capture-time check cannot tell it from an older file), but the stop
asked "is the camera firing and saving there?" of a camera that did both and called the file
"a late file of an earlier pulse?" (no pulse of the run came before it); the resume then stopped
again on the camera clock the run had learned, and the clock file to delete was named only
then.
"""

from __future__ import annotations

import datetime
import sys
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import folder_watch_config, tethered_run
from dng_spec_writer import dng, mosaic_from_rgb

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: the camera clock's reading at the board's time 0
CAMERA_EPOCH = datetime.datetime(2026, 11, 30, 9, 0, 0)


class StampingCamera(threading.Thread):
    """A camera fired by the board's shutter line: each pulse's DNG is saved into ``folder``,
    stamped with the camera clock at the pulse (the board's time of it, plus ``offset_s``,
    in whole seconds as EXIF keeps them); ``set_back_after`` shots later its owner sets the
    clock back an hour."""

    def __init__(
        self, firmware: Any, folder: Path, set_back_after: int | None, offset_s: float
    ) -> None:
        super().__init__(daemon=True)
        self.firmware, self.folder = firmware, folder
        self.set_back_after = set_back_after
        self.offset_s = offset_s
        self.saved = 0
        self.numbered = len(list(folder.iterdir()))  # its file counter goes on
        self.stop = threading.Event()

    def run(self) -> None:
        mosaic = mosaic_from_rgb(np.full((32, 48, 3), 0.3), "RGGB", (0,) * 4, 4095)
        while not self.stop.is_set():
            pulses = [e for e in list(self.firmware.history) if e.what == "shutter"]
            while self.saved < len(pulses):
                if self.saved == self.set_back_after:
                    self.offset_s -= 3600.0
                at = pulses[self.saved].time_s + self.offset_s
                stamp = CAMERA_EPOCH + datetime.timedelta(seconds=at)
                self.saved += 1
                data = dng(
                    mosaic, "RGGB", (0,) * 4, 4095, date_time=stamp.strftime("%Y:%m:%d %H:%M:%S")
                )
                (self.folder / f"IMG_{self.numbered + self.saved:04d}.DNG").write_bytes(data)
            self.stop.wait(0.02)


def _run(
    monkeypatch: pytest.MonkeyPatch,
    cfg: Path,
    tether: Path,
    out: Path,
    set_back_after: int | None,
    offset_s: float = 0.0,
    resume: bool = False,
) -> tuple[Any, str, list[int]]:
    """:func:`conftest.tethered_run` of 4 lights into ``out`` (or its ``resume``) with a
    :class:`StampingCamera`: the result, its words and the LEDs lit at the end."""
    return tethered_run(
        monkeypatch,
        cfg,
        tether,
        [],
        out,
        camera=lambda firmware: StampingCamera(firmware, tether, set_back_after, offset_s),
        lights=4,
        resume=resume,
    )


def test_a_camera_clock_set_back_mid_session_is_said_with_the_way_out(tmp_path, monkeypatch):
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = folder_watch_config(tmp_path, tether, timeout_s=10.0)
    out = tmp_path / "s"
    r, said, lit = _run(monkeypatch, cfg, tether, out, 2)
    assert r.exit_code == 2, said
    assert "Traceback" not in said and not lit, said
    assert "is the camera firing" not in said, said
    assert "late file of an earlier pulse" not in said, said
    # the first words say what happened: the pulse's file came and was set aside, and why
    assert said.split("error: ", 1)[1].startswith(
        "folder-camera during 'wait for file': IMG_0003.DNG came after the pulse but was set "
        "aside, shot before this run's first image; no other new file matching"
    ), said
    assert "it was shot before this run's first image (IMG_0003.DNG 3" in said, said
    clock_file = out / "raw" / ".folder_watch_clock.json"
    assert f"delete {clock_file} and resume" in said, said
    assert (tether / "IMG_0003.DNG").is_file()  # left where it was

    clock_file.unlink()  # the way out the stop gave
    # the camera's clock stays set back
    r, said, lit = _run(monkeypatch, cfg, tether, out, None, -3600.0, resume=True)
    assert r.exit_code == 0, said
    assert (out / "lights.lp").read_text().split()[0] == "4"
