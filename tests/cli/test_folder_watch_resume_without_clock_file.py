"""A resume of a session that keeps no camera clock (a session of an older version, or its
``raw/.folder_watch_clock.json`` deleted), through `rti-rig run --resume` on the shipped
folder-watch example (its dome firmware emulated on a pty, its camera a thread that saves a
DNG stamped with the camera's clock for each shutter pulse the board saw).

The stopped run's last shot comes into the folder only during the resume, after its first
image: it is rightly not taken. The stop called it shot "before this run's first image …: the
camera's clock was set back since … or an older picture was copied into the folder", leaving
out what fits best and is known: the earlier run's kept images hold capture times, and this
file was shot after its last one, as the shot the earlier run stopped waiting for was. What
is not known, without the clock file, is whether the camera's clock changed between the runs.
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


def _dng(at_s: float) -> bytes:
    stamp = CAMERA_EPOCH + datetime.timedelta(seconds=at_s)
    mosaic = mosaic_from_rgb(np.full((32, 48, 3), 0.3), "RGGB", (0,) * 4, 4095)
    return dng(mosaic, "RGGB", (0,) * 4, 4095, date_time=stamp.strftime("%Y:%m:%d %H:%M:%S"))


class Camera(threading.Thread):
    """A camera fired by the board's shutter line whose clock is never changed: it saves the
    DNG of each pulse in ``saves`` (1-based, this run's), stamped at ``stamp_of(pulse times,
    n)`` seconds, as ``IMG_<counter>.DNG``; a pulse not in ``saves`` gives no file (lost on
    the way). Its file counter goes on from the files already in ``folder``."""

    def __init__(self, firmware: Any, folder: Path, saves: dict[int, Any]) -> None:
        super().__init__(daemon=True)
        self.firmware, self.folder, self.saves = firmware, folder, saves
        self.numbered = len(list(folder.iterdir()))
        self.handled = 0
        self.stop = threading.Event()

    def run(self) -> None:
        while not self.stop.is_set():
            pulses = [e.time_s for e in list(self.firmware.history) if e.what == "shutter"]
            while self.handled < len(pulses):
                self.handled += 1
                stamp_of = self.saves.get(self.handled)
                if stamp_of is not None:
                    self.numbered += 1
                    data = _dng(stamp_of(pulses))
                    (self.folder / f"IMG_{self.numbered:04d}.DNG").write_bytes(data)
            self.stop.wait(0.02)


def test_a_late_file_of_the_earlier_run_in_a_resume_without_clock_file_says_what_is_known(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    # pulses at least 1.5 s apart: EXIF keeps whole seconds, and at the shipped 0.2 s settle
    # the late shot and the last kept one could carry the same second
    cfg = folder_watch_config(tmp_path, tether, timeout_s=8.0, settle_s=1.5)
    out = tmp_path / "s"
    cameras: list[Camera] = []

    def first(firmware: Any) -> Camera:
        # pulses 1 and 2 give their shots; pulse 3's file is late (it comes during the resume)
        cameras.append(Camera(firmware, tether, {k: lambda p, k=k: p[k - 1] for k in (1, 2)}))
        return cameras[-1]

    r, said, lit = tethered_run(monkeypatch, cfg, tether, [], out, camera=first, lights=4)
    assert r.exit_code == 2 and not lit, said
    assert "no new file matching" in said, said
    clock_file = out / "raw" / ".folder_watch_clock.json"
    clock_file.unlink()  # an older session's, or deleted
    pulses = [e.time_s for e in list(cameras[0].firmware.history) if e.what == "shutter"]
    assert len(pulses) == 3, pulses
    pulse_3 = pulses[2]  # the pulse the run stopped waiting for

    def resumed(firmware: Any) -> Camera:
        # the resume's first pulse gives its own shot; at its second, the stopped run's late
        # file (shot at that run's pulse 3) comes in, and the second pulse's own file is lost
        return Camera(firmware, tether, {1: lambda pulses: pulses[0], 2: lambda _: pulse_3})

    r, said, lit = tethered_run(
        monkeypatch, cfg, tether, [], out, camera=resumed, lights=4, resume=True
    )
    assert r.exit_code == 2 and not lit, said
    assert "Traceback" not in said, said
    assert "IMG_0004.DNG" in said, said  # the late file, named
    assert "keeps no camera clock from its earlier run" in said, said
    assert "whether the camera's clock was changed between the runs is not known" in said, said
    assert "shot after the earlier run's last kept image (raw/image_002.dng" in said, said
    assert "a late file of the earlier run's last pulse (the shot it stopped waiting for)" in said
    # not the words that left the late file out: "the camera's clock was set back since … or
    # an older picture was copied into the folder"
    assert "so no pulse of this run took it: the camera's clock was set back" not in said, said


def test_files_shot_before_the_earlier_runs_last_kept_image_are_said_in_the_plural(
    tmp_path: Path,
) -> None:
    """Two files of a resume without a clock file, both shot before the earlier run's last
    kept image: the stop said "they were shot before … so it is no late file", one file's
    words for two."""
    from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
    from rti_rig.drivers.cameras.settings import FolderWatchSettings

    raw = tmp_path / "s" / "raw"
    raw.mkdir(parents=True)
    (raw / "image_001.dng").write_bytes(_dng(100.0))  # the earlier run's last kept shot
    tether = tmp_path / "tether"
    tether.mkdir()
    camera = FolderWatchCamera(FolderWatchSettings(folder=tether))
    camera.output_dir = raw / ".incoming"  # as the session binds it
    camera._earlier_last = camera._earlier_run_last_shot()
    assert camera._earlier_last is not None and camera._earlier_last[1] is not None
    taken = camera._earlier_last[1]
    said = camera._without_clock_said({"IMG_0004.DNG": taken - 50, "IMG_0005.DNG": taken - 40})
    assert "they were shot before the earlier run's last kept image" in said, said
    assert "so none of them is a late file of the shot that run stopped waiting" in said, said
    said = camera._without_clock_said({"IMG_0004.DNG": taken - 50})
    assert "it was shot before" in said and "so it is no late file" in said, said


def test_the_earlier_runs_last_kept_image_is_the_highest_number_not_the_last_name(
    tmp_path: Path,
) -> None:
    """``raw/image_1000`` is kept after ``raw/image_999``: by name it sorted first, and the
    resume dated its files by image 999's capture time."""
    from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
    from rti_rig.drivers.cameras.settings import FolderWatchSettings

    raw = tmp_path / "s" / "raw"
    raw.mkdir(parents=True)
    (raw / "image_999.dng").write_bytes(_dng(100.0))
    (raw / "image_1000.dng").write_bytes(_dng(160.0))  # the earlier run's last kept shot
    tether = tmp_path / "tether"
    tether.mkdir()
    camera = FolderWatchCamera(FolderWatchSettings(folder=tether))
    camera.output_dir = raw / ".incoming"  # as the session binds it
    last = camera._earlier_run_last_shot()
    assert last is not None and last[0] == "raw/image_1000.dng", last
    earlier = FolderWatchCamera(FolderWatchSettings(folder=tether))
    earlier.output_dir = raw / ".incoming"
    (raw / "image_1000.dng").unlink()
    only = earlier._earlier_run_last_shot()
    assert only is not None and last[1] is not None and only[1] is not None
    assert last[1] - only[1] == pytest.approx(60.0)  # its own capture time, not image 999's
