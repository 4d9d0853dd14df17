"""Folder watch: a tethering program that saves under one name and renames afterwards.

Many do (``capt0000.CR2`` → ``IMG_0001.CR2``, or a hidden ``.IMG_0001.CR2`` temporary →
``IMG_0001.CR2``). Taken by name alone, the renamed file had been a new file: the next light's
image was the previous light's picture, and every later image one light off, with no error.
The same happened to the JPEG of a RAW+JPEG shot when the patterns matched both.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scripted_clock import ScriptedClock

from rti_rig.core.clock import VirtualClock
from rti_rig.core.errors import CaptureError
from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic, write_dng
from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
from rti_rig.drivers.cameras.settings import FolderWatchSettings


def dng(path, level):
    mosaic = linear_to_mosaic(np.full((32, 32), level), "RGGB", 256, 4095)
    return write_dng(path, mosaic, black_level=256, white_level=4095, exposure_s=0.5, iso=100)


def level_of(frame) -> float:
    return float(np.mean(frame.pixels) / frame.white_level)


def camera(tmp_path, actions, patterns=("*.DNG",), **kw):
    settings = FolderWatchSettings(
        folder=tmp_path, timeout_s=4.0, poll_interval_s=0.125, patterns=patterns, **kw
    )
    cam = FolderWatchCamera(settings, clock=ScriptedClock(actions))
    cam.connect()
    return cam


def test_a_file_renamed_after_it_was_taken_is_not_the_next_shot(tmp_path):
    # shot 1 saved as capt0000.DNG, renamed once written; shot 2 saved as IMG_0002.DNG
    actions = {
        0.25: lambda: dng(tmp_path / "capt0000.DNG", 0.2),
        1.0: lambda: (tmp_path / "capt0000.DNG").rename(tmp_path / "IMG_0001.DNG"),
        2.0: lambda: dng(tmp_path / "IMG_0002.DNG", 0.6),
    }
    cam = camera(tmp_path, actions)
    first = cam.capture(0.5)
    assert level_of(first) == pytest.approx(0.2, abs=1e-3)
    second = cam.capture(0.5)
    assert second.metadata["originals"][0]["name"] == "IMG_0002.DNG"
    assert level_of(second) == pytest.approx(0.6, abs=1e-3)


def test_a_hidden_temporary_is_not_taken_its_final_name_is(tmp_path):
    def save_hidden(name, level):
        dng(tmp_path / f".{name}", level)

    actions = {
        0.25: lambda: save_hidden("IMG_0001.DNG", 0.2),
        1.0: lambda: (tmp_path / ".IMG_0001.DNG").rename(tmp_path / "IMG_0001.DNG"),
        2.0: lambda: save_hidden("IMG_0002.DNG", 0.6),
        3.0: lambda: (tmp_path / ".IMG_0002.DNG").rename(tmp_path / "IMG_0002.DNG"),
    }
    cam = camera(tmp_path, actions)
    first = cam.capture(0.5)
    assert first.metadata["originals"][0]["name"] == "IMG_0001.DNG"
    assert level_of(first) == pytest.approx(0.2, abs=1e-3)
    second = cam.capture(0.5)
    assert second.metadata["originals"][0]["name"] == "IMG_0002.DNG"
    assert level_of(second) == pytest.approx(0.6, abs=1e-3)


def test_a_file_present_at_connect_and_renamed_is_not_a_shot(tmp_path):
    dng(tmp_path / "old.DNG", 0.9)
    cam = camera(tmp_path, {0.25: lambda: (tmp_path / "old.DNG").rename(tmp_path / "X.DNG")})
    with pytest.raises(CaptureError, match="no new file"):
        cam.capture(0.5)


def test_a_name_used_again_by_another_file_is_refused_and_said_so(tmp_path):
    # every shot saved as capt0000.DNG, the previous one renamed first: the second capt0000 is
    # never taken (a name is used once), and the timeout says why
    actions = {
        0.25: lambda: dng(tmp_path / "capt0000.DNG", 0.2),
        1.0: lambda: (tmp_path / "capt0000.DNG").rename(tmp_path / "IMG_0001.DNG"),
        1.5: lambda: dng(tmp_path / "capt0000.DNG", 0.6),
    }
    cam = camera(tmp_path, actions)
    cam.capture(0.5)
    with pytest.raises(CaptureError, match=r"capt0000\.DNG appeared again.*its own file name"):
        cam.capture(0.5)


def jpeg(path, level):
    import cv2

    code = round(255 * level ** (1 / 2.2))
    assert cv2.imwrite(str(path), np.full((32, 32, 3), code, np.uint8))


@pytest.mark.parametrize("jpeg_first", [False, True])
def test_raw_plus_jpeg_is_one_shot_and_its_raw_the_image(tmp_path, jpeg_first):
    """A camera set to RAW+JPEG, both matched: the JPEG had been the next light's image."""

    def shot(n, level):
        if jpeg_first:
            jpeg(tmp_path / f"IMG_000{n}.JPG", level)
        dng(tmp_path / f"IMG_000{n}.DNG", level)
        if not jpeg_first:
            jpeg(tmp_path / f"IMG_000{n}.JPG", level)

    actions = {0.25: lambda: shot(1, 0.2), 2.0: lambda: shot(2, 0.6)}
    cam = camera(tmp_path, actions, ("*.DNG", "*.JPG"), eight_bit_response="srgb")
    first, second = cam.capture(0.5), cam.capture(0.5)
    assert [f.metadata["originals"][0]["name"] for f in (first, second)] == [
        "IMG_0001.DNG",
        "IMG_0002.DNG",
    ]
    assert level_of(second) == pytest.approx(0.6, abs=1e-3)


def test_the_jpeg_of_a_raw_shot_arriving_late_is_not_the_next_shot(tmp_path):
    actions = {
        0.25: lambda: dng(tmp_path / "IMG_0001.DNG", 0.2),
        1.0: lambda: jpeg(tmp_path / "IMG_0001.JPG", 0.2),  # after the RAW was taken
        2.0: lambda: dng(tmp_path / "IMG_0002.DNG", 0.6),
    }
    cam = camera(tmp_path, actions, ("*.DNG", "*.JPG"), eight_bit_response="srgb")
    cam.capture(0.5)
    second = cam.capture(0.5)
    assert second.metadata["originals"][0]["name"] == "IMG_0002.DNG"


@pytest.mark.parametrize("suffix", [".DNG", ".tif"])
def test_a_writer_that_pauses_longer_than_the_polls_still_gives_the_shot(tmp_path, suffix):
    """Half a file, steady for the stability polls (the writer paused), then the rest: it had
    stopped the session with a decode error, the shot lost though the file was on its way."""
    import tifffile

    whole = tmp_path / "whole.bin"
    if suffix == ".DNG":
        dng(whole, 0.4)
    else:
        tifffile.imwrite(whole, np.full((32, 32, 3), 26214, np.uint16), photometric="rgb")
    data = whole.read_bytes()
    whole.unlink()
    target = tmp_path / f"IMG_0001{suffix}"
    actions = {
        0.25: lambda: target.write_bytes(data[: len(data) // 2]),
        2.0: lambda: target.write_bytes(data),
    }
    cam = camera(tmp_path, actions, (f"*{suffix}",))
    frame = cam.capture(0.5)
    assert level_of(frame) == pytest.approx(0.4, abs=1e-3)


def test_a_file_that_stays_cut_short_is_an_error_naming_it_and_what_to_raise(tmp_path):
    whole = tmp_path / "whole.bin"
    dng(whole, 0.4)
    data = whole.read_bytes()
    whole.unlink()
    actions = {0.25: lambda: (tmp_path / "IMG_0001.DNG").write_bytes(data[: len(data) // 2])}
    cam = camera(tmp_path, actions)
    with pytest.raises(
        CaptureError, match=r"IMG_0001\.DNG did not change within 4 s.*stable_polls"
    ):
        cam.capture(0.5)


def test_an_eight_bit_file_is_refused_at_once_not_waited_on(tmp_path):
    cam = camera(tmp_path, {0.25: lambda: jpeg(tmp_path / "IMG_0001.JPG", 0.2)}, ("*.JPG",))
    with pytest.raises(CaptureError, match="8-bit"):
        cam.capture(0.5)
    assert cam._clock.now() < 1.0


def test_a_file_there_before_the_pulse_is_not_the_pulses_picture(tmp_path):
    """An extra file (a duplicate copy, a test shot) had been taken as the next light's image,
    every later image one light off. With a trigger, the pulse's picture comes after it."""
    shots = iter([0.2, 0.4, 0.6])
    count = iter(range(1, 4))

    def pulse(exposure_s):
        n, level = next(count), next(shots)
        dng(tmp_path / f"IMG_000{n}.DNG", level)
        if n == 1:
            dng(tmp_path / "IMG_0001_copy.DNG", level)  # a second file for one shot

    settings = FolderWatchSettings(
        folder=tmp_path, timeout_s=4.0, poll_interval_s=0.125, patterns=("*.DNG",)
    )
    cam = FolderWatchCamera(settings, clock=VirtualClock(), trigger=pulse)
    cam.connect()
    frames = [cam.capture(0.5) for _ in range(3)]
    assert [f.metadata["originals"][0]["name"] for f in frames] == [
        "IMG_0001.DNG",
        "IMG_0002.DNG",
        "IMG_0003.DNG",
    ]
    assert [round(level_of(f), 2) for f in frames] == [0.2, 0.4, 0.6]
    assert frames[1].metadata["stray_files"] == ["IMG_0001_copy.DNG"]
    assert any("IMG_0001_copy.DNG" in n for n in frames[1].metadata["notices"])


#: 2026-11-30 09:00:00 UTC, the day the _Body's camera clock counts from
WALL_AT_ZERO = 1796029200.0


def exif_tiff(path, level, stamp):
    """A 16-bit grey TIFF with EXIF DateTimeOriginal ``stamp`` (a datetime) in its EXIF IFD,
    as tethering programs and raw converters write it (Pillow writes the EXIF IFD)."""
    from PIL import Image, TiffImagePlugin

    ifd = TiffImagePlugin.ImageFileDirectory_v2()
    ifd[0x8769] = {0x9003: stamp.strftime("%Y:%m:%d %H:%M:%S")}
    image = Image.fromarray(np.full((32, 32), round(65535 * level), np.uint16))
    image.save(path, tiffinfo=ifd)


class _Body:
    """A camera fired by the dome's shutter line, its tethering program saving each shot's DNG
    ``delays[n]`` s after the n-th pulse (on the test's clock), stamped with the camera clock's
    DateTime (whole seconds, ``offset_s`` from the rig's clock: another time zone)."""

    def __init__(self, folder, delays, offset_s=3600.0 * 5 + 17.4, tiff=False):
        self.folder, self.delays, self.offset_s = folder, list(delays), offset_s
        self.clock = ScriptedClock({})
        self.pulses: list[float] = []
        #: save 16-bit TIFFs with EXIF DateTimeOriginal (as a tethering program exports them)
        self.tiff = tiff

    def wall(self) -> float:
        """The computer's wall clock: the test's clock, counted from 2026-11-30 09:00 UTC."""
        return WALL_AT_ZERO + self.clock.now()

    def pulse(self, exposure_s: float) -> None:
        import datetime

        n, at = len(self.pulses) + 1, self.clock.now()
        self.pulses.append(at)
        stamp = datetime.datetime(2026, 11, 30, 9, 0, 0) + datetime.timedelta(
            seconds=at + self.offset_s
        )
        mosaic = linear_to_mosaic(np.full((32, 32), 0.1 * n), "RGGB", 256, 4095)

        def save() -> None:
            if self.tiff:
                exif_tiff(self.folder / f"IMG_{n:04d}.tif", 0.1 * n, stamp)
                return
            write_dng(
                self.folder / f"IMG_{n:04d}.DNG",
                mosaic,
                black_level=256,
                white_level=4095,
                exposure_s=exposure_s,
                date_time=stamp.strftime("%Y:%m:%d %H:%M:%S"),
            )

        self.clock.actions = sorted([*self.clock.actions, (at + self.delays[n - 1], save)])


def test_a_file_late_past_a_stopped_run_does_not_put_the_resumed_images_one_light_off(tmp_path):
    """Pulse 2's file comes 20 s late, after the run stopped at timeout_s = 15 s; the resume
    pulses light 2 again, 10 s later, and the late file comes after that pulse: taken for light
    2 (its light). The resumed pulse's own file comes after the next pulse and had been taken
    for light 3, every later image one light off. Its capture time (17 s after the image
    before, the pulses 3.25 s apart) now sets it aside in strays, and light 3 gets its own
    file, which fits it as the next pulse's."""
    # n-th pulse's file delay: 1 s, then pulse 2's 20 s (past the timeout), then the resumed
    # run's: pulse 3 (light 2 again) 4 s, after the late file; pulses 4 and 5 (lights 3, 4) 1.5 s
    body = _Body(tmp_path, [1.0, 20.0, 4.0, 1.5, 1.5])
    settings = FolderWatchSettings(
        folder=tmp_path, timeout_s=15.0, poll_interval_s=0.125, shutter_lag_s=0.25
    )

    def camera() -> FolderWatchCamera:
        return FolderWatchCamera(settings, clock=body.clock, trigger=body.pulse)

    first = camera()
    first.connect()
    assert first.capture(0.5).metadata["watched_file"].endswith("IMG_0001.DNG")
    with pytest.raises(CaptureError, match="within 15 s"):
        first.capture(0.5)  # light 2: the run stops
    first.close()
    body.clock.sleep(2.0)  # the user resumes: pulse 2's file is still on its way
    resumed = camera()
    resumed.connect()
    got = []
    for _ in range(3):  # lights 2, 3, 4
        frame = resumed.capture(0.5)
        got.append((Path(frame.metadata["watched_file"]).name, frame.metadata.get("notices")))
    names = [n for n, _ in got]
    # light 2: the late file (a shot of light 2); light 3: pulse 4's; light 4: pulse 5's
    assert names == ["IMG_0002.DNG", "IMG_0004.DNG", "IMG_0005.DNG"], got
    said = " ".join(got[1][1] or [])
    assert "IMG_0003.DNG" in said and "shot out of step" in said, said
    assert "late file of an earlier pulse" in said, said
    assert not got[0][1] and not got[2][1], got


def test_files_in_step_with_the_pulses_are_all_taken_whatever_the_camera_clock(tmp_path):
    """Files coming up to a few seconds late, the camera clock hours off: every one taken."""
    body = _Body(tmp_path, [3.0, 0.2, 4.0, 1.0], offset_s=-7 * 3600 + 0.9)
    cam = FolderWatchCamera(
        FolderWatchSettings(folder=tmp_path, timeout_s=10.0, poll_interval_s=0.125),
        clock=body.clock,
        trigger=body.pulse,
    )
    cam.connect()
    names = [Path(cam.capture(0.5).metadata["watched_file"]).name for _ in range(4)]
    assert names == [f"IMG_{n:04d}.DNG" for n in range(1, 5)]


def test_a_pulse_whose_confirmation_was_lost_keeps_its_own_file(tmp_path):
    """Pulse 2's reply is lost: the trigger returns a whole reply timeout (1 s) after the real
    pulse. The pulse had been dated when the trigger returned, so its own file (camera clock
    at .05 s) read 1 s out of step and was set aside, the run stopping with "a late file of an
    earlier pulse?". The pulse is now dated within the trigger's call."""
    from rti_rig.drivers.cameras.folder_watch import TriggerUnconfirmed

    body = _Body(tmp_path, [0.5, 0.5, 0.5], offset_s=0.05)

    def pulse(exposure_s: float) -> None:
        body.pulse(exposure_s)
        if len(body.pulses) == 2:
            body.clock.sleep(1.0)
            raise TriggerUnconfirmed("dome: no reply within 1 s")

    settings = FolderWatchSettings(folder=tmp_path, timeout_s=5.0, poll_interval_s=0.125)
    cam = FolderWatchCamera(settings, clock=body.clock, trigger=pulse)
    cam.connect()
    assert cam.capture(0.1).metadata["watched_file"].endswith("IMG_0001.DNG")
    body.clock.sleep(2.9 - (body.clock.now() - body.pulses[0]))
    second = cam.capture(0.1)
    assert second.metadata["watched_file"].endswith("IMG_0002.DNG")
    assert any("confirmation was lost" in n for n in second.metadata.get("notices") or [])


def test_a_late_file_still_being_written_is_checked_once_whole(tmp_path):
    """A file shot 30 s out of step comes half written 0.3 s after pulse 2 (a network share
    pausing), then whole 1 s later; pulse 2's own file comes 2.5 s after its pulse. Half a
    file gave LibRaw no capture time and the file was taken for light 2 unchecked. Its time is
    now read once it is whole: it is set aside and light 2 gets its own file."""
    import datetime

    body = _Body(tmp_path, [0.5, 2.5, 0.5], offset_s=0.0)
    stale = tmp_path.parent / "stale.dng"
    stamp = datetime.datetime(2026, 11, 30, 9, 0, 0) - datetime.timedelta(seconds=30)
    write_dng(
        stale,
        linear_to_mosaic(np.full((64, 64), 0.9), "RGGB", 256, 4095),
        black_level=256,
        white_level=4095,
        exposure_s=0.1,
        date_time=stamp.strftime("%Y:%m:%d %H:%M:%S"),
    )
    data = stale.read_bytes()
    late = tmp_path / "IMG_0000.DNG"

    def pulse(exposure_s: float) -> None:
        body.pulse(exposure_s)
        if len(body.pulses) == 2:
            at = body.clock.now()
            body.clock.actions = sorted(
                [
                    *body.clock.actions,
                    (at + 0.3, lambda: late.write_bytes(data[: len(data) // 2])),
                    (at + 1.3, lambda: late.write_bytes(data)),
                ],
                key=lambda a: a[0],
            )

    settings = FolderWatchSettings(folder=tmp_path, timeout_s=5.0, poll_interval_s=0.125)
    cam = FolderWatchCamera(settings, clock=body.clock, trigger=pulse)
    cam.connect()
    cam.capture(0.1)
    body.clock.sleep(3.0)
    second = cam.capture(0.1)
    assert second.metadata["watched_file"].endswith("IMG_0002.DNG"), second.metadata


def test_a_capture_time_does_not_jump_at_the_computers_daylight_saving_change(
    tmp_path, monkeypatch
):
    """EXIF times carry no time zone; read in the computer's zone, two shots 3 s apart across
    its daylight-saving change (America/New_York, 2026-11-01 02:00) came out 3603 s apart, and
    every later file was set aside as out of step. They are the camera's wall clock."""
    import time

    from rti_rig.drivers.cameras.folder_watch import capture_time

    monkeypatch.setenv("TZ", "America/New_York")
    time.tzset()
    try:
        times = []
        for name, stamp in (("a.DNG", "2026:11:01 01:59:58"), ("b.DNG", "2026:11:01 02:00:01")):
            write_dng(
                tmp_path / name,
                linear_to_mosaic(np.full((32, 32), 0.5), "RGGB", 256, 4095),
                black_level=256,
                white_level=4095,
                exposure_s=0.1,
                date_time=stamp,
            )
            times.append(capture_time(tmp_path / name))
    finally:
        monkeypatch.delenv("TZ")
        time.tzset()
    assert times[1] - times[0] == pytest.approx(3.0)


def _stopped_and_resumed(tmp_path, session):
    """The stopped-run scenario of the test above, with the camera bound to ``session`` (or
    not): pulse 2's file is 20 s late, the run stops at timeout_s = 15 s, the user resumes 2 s
    later; the late file then comes before the resumed pulse's own file. The names taken for
    lights 2, 3, 4 after the resume, and their notices."""
    body = _Body(tmp_path, [1.0, 20.0, 4.0, 1.5, 1.5])
    settings = FolderWatchSettings(
        folder=tmp_path, timeout_s=15.0, poll_interval_s=0.125, shutter_lag_s=0.25
    )

    def camera() -> FolderWatchCamera:
        cam = FolderWatchCamera(settings, clock=body.clock, trigger=body.pulse, wall=body.wall)
        cam.output_dir = None if session is None else session / "raw" / ".incoming"
        return cam

    first = camera()
    first.connect()
    first.capture(0.5)
    with pytest.raises(CaptureError, match="within 15 s"):
        first.capture(0.5)
    first.close()
    body.clock.sleep(2.0)
    resumed = camera()
    resumed.connect()
    got = []
    for _ in range(3):
        frame = resumed.capture(0.5)
        got.append((Path(frame.metadata["watched_file"]).name, frame.metadata.get("notices")))
    return got


def test_a_resumes_first_file_shot_before_it_connected_is_set_aside(tmp_path):
    """The first image after a connect had no earlier image to be checked against: the late
    file of the pulse the stopped run waited for, shot 17 s before the resume, was taken as the
    resumed light's image. The camera clock learned in the first run (kept in the session's
    raw/) now dates it before the resume: it is set aside and the resumed pulse's own file
    taken; every image after it is its own pulse's."""
    tether, session = tmp_path / "tether", tmp_path / "session"
    tether.mkdir()
    got = _stopped_and_resumed(tether, session)
    assert [n for n, _ in got] == ["IMG_0003.DNG", "IMG_0004.DNG", "IMG_0005.DNG"], got
    said = " ".join(got[0][1] or [])
    assert "IMG_0002.DNG" in said and "shot before this run connected" in said, said
    assert not got[1][1] and not got[2][1], got
    assert (session / "raw" / ".folder_watch_clock.json").is_file()


def test_a_resume_hours_later_takes_its_own_files_despite_clock_drift(tmp_path):
    """A clean resume 8 hours after the first run, the camera clock having drifted 2 s behind
    the computer's meanwhile (70 ppm): its first file is not refused."""
    session = tmp_path / "session"
    tether = tmp_path / "tether"
    tether.mkdir()
    body = _Body(tether, [0.5] * 4, offset_s=0.3)
    settings = FolderWatchSettings(folder=tether, timeout_s=5.0, poll_interval_s=0.125)

    def camera() -> FolderWatchCamera:
        cam = FolderWatchCamera(settings, clock=body.clock, trigger=body.pulse, wall=body.wall)
        cam.output_dir = session / "raw" / ".incoming"
        cam.connect()
        return cam

    first = camera()
    first.capture(0.1)
    first.capture(0.1)
    first.close()
    body.clock.sleep(8 * 3600.0)
    body.offset_s -= 2.0
    resumed = camera()
    names = [Path(resumed.capture(0.1).metadata["watched_file"]).name for _ in range(2)]
    assert names == ["IMG_0003.DNG", "IMG_0004.DNG"]


def test_a_tiffs_exif_capture_time_is_checked_against_the_pulses(tmp_path):
    """A TIFF's EXIF DateTimeOriginal is its capture time: a TIFF shot 30 s out of step that
    comes after pulse 2, before pulse 2's own file, had been taken for light 2 (a TIFF had no
    capture time at all). It is set aside and light 2 gets its own file."""
    import datetime

    body = _Body(tmp_path, [0.5, 2.5, 0.5], offset_s=0.0, tiff=True)
    stale = datetime.datetime(2026, 11, 30, 9, 0, 0) - datetime.timedelta(seconds=30)

    def pulse(exposure_s: float) -> None:
        body.pulse(exposure_s)
        if len(body.pulses) == 2:
            late = (body.clock.now() + 0.5, lambda: exif_tiff(tmp_path / "OLD.tif", 0.9, stale))
            body.clock.actions = sorted([*body.clock.actions, late], key=lambda a: a[0])

    settings = FolderWatchSettings(
        folder=tmp_path, timeout_s=5.0, poll_interval_s=0.125, patterns=("*.tif",)
    )
    cam = FolderWatchCamera(settings, clock=body.clock, trigger=pulse)
    cam.connect()
    cam.capture(0.1)
    body.clock.sleep(3.0)
    second = cam.capture(0.1)
    assert second.metadata["watched_file"].endswith("IMG_0002.tif"), second.metadata
    assert second.metadata["stray_files"] == ["OLD.tif"]


def test_a_file_with_no_capture_time_is_said_to_be_unchecked(tmp_path):
    """A PNG (OpenCV reads no EXIF) or a TIFF without DateTimeOriginal cannot be checked
    against the pulses: the image says so, in one text the session summary counts, rather
    than pass for checked."""
    import cv2

    def pulse(exposure_s: float) -> None:
        cv2.imwrite(str(tmp_path / "IMG_0001.png"), np.full((32, 32), 30000, np.uint16))

    settings = FolderWatchSettings(
        folder=tmp_path, timeout_s=5.0, poll_interval_s=0.125, patterns=("*.png",)
    )
    cam = FolderWatchCamera(settings, clock=VirtualClock(), trigger=pulse)
    cam.connect()
    notices = cam.capture(0.1).metadata.get("notices") or []
    assert any("holds no capture time" in n and "not checked" in n for n in notices), notices


def test_a_refused_first_file_leaves_no_camera_clock_in_the_session(tmp_path):
    """The camera clock is kept in the session's raw/ only once an image's file is decoded: a
    first file refused (exposed 0.5 s where 0.1 s was asked) leaves no raw/ folder, so the
    session still holds nothing and may be used again."""
    session, tether = tmp_path / "session", tmp_path / "tether"
    tether.mkdir()
    body = _Body(tether, [0.5], offset_s=0.0)
    settings = FolderWatchSettings(folder=tether, timeout_s=5.0, poll_interval_s=0.125)
    cam = FolderWatchCamera(
        settings, clock=body.clock, trigger=lambda _: body.pulse(0.5), wall=body.wall
    )
    cam.output_dir = session / "raw" / ".incoming"
    cam.connect()
    with pytest.raises(CaptureError, match="set the camera to manual"):
        cam.capture(0.1)
    assert not (session / "raw").exists()


def test_a_camera_clock_set_back_between_runs_is_said_with_the_way_out(tmp_path):
    """The owner set the camera's clock back an hour between the stop and the resume: every
    file now looks shot before the resume. The stop says so, naming the session's clock file
    to delete; deleted, the next resume takes its files (its first image unchecked)."""
    session, tether = tmp_path / "session", tmp_path / "tether"
    tether.mkdir()
    body = _Body(tether, [0.5] * 4, offset_s=0.0)
    settings = FolderWatchSettings(folder=tether, timeout_s=3.0, poll_interval_s=0.125)

    def camera() -> FolderWatchCamera:
        cam = FolderWatchCamera(settings, clock=body.clock, trigger=body.pulse, wall=body.wall)
        cam.output_dir = session / "raw" / ".incoming"
        cam.connect()
        return cam

    camera().capture(0.1)
    body.clock.sleep(60.0)
    body.offset_s -= 3600.0
    with pytest.raises(CaptureError) as info:
        camera().capture(0.1)
    said = info.value.message
    clock_file = session / "raw" / ".folder_watch_clock.json"
    assert "IMG_0002.DNG" in said and "shot before this run connected" in said, said
    assert "set back" in said and str(clock_file) in said, said
    assert "the computer's clock set forward" in said, said
    clock_file.unlink()
    frame = camera().capture(0.1)
    assert frame.metadata["watched_file"].endswith("IMG_0003.DNG")


def _resumed_after(tmp_path, wall_step_s, computer_after="this-computer"):
    """A session whose first run took one image, resumed a minute later after the computer's
    wall clock was moved ``wall_step_s`` (its monotonic clock, the rig's, not), on the computer
    ``computer_after``: the resumed camera and the session's clock file."""
    session, tether = tmp_path / "session", tmp_path / "tether"
    tether.mkdir()
    body = _Body(tether, [0.5] * 4, offset_s=0.0)
    camera = _ComputerClocks(body, 3.0, session)
    camera("this-computer").capture(0.1)
    body.clock.sleep(60.0)
    camera.step_s = wall_step_s
    return camera(computer_after)


class _ComputerClocks:
    """Makes the session's folder-watch cameras on ``body``'s clock, on a named computer: its
    wall clock ``step_s`` off the test's, its clock since boot ``lost_s`` behind the rig's."""

    def __init__(self, body, timeout_s, session):
        self.body, self.session, self.step_s, self.lost_s = body, session, 0.0, 0.0
        self.settings = FolderWatchSettings(
            folder=body.folder, timeout_s=timeout_s, poll_interval_s=0.125
        )

    def __call__(self, computer: str) -> FolderWatchCamera:
        body = self.body
        cam = FolderWatchCamera(
            self.settings,
            clock=body.clock,
            trigger=body.pulse,
            wall=lambda: body.wall() + self.step_s,
            monotonic=lambda: body.clock.now() - self.lost_s,
            computer=lambda: computer,
        )
        cam.output_dir = self.session / "raw" / ".incoming"
        cam.connect()
        return cam


def test_a_resume_after_the_computers_clock_was_stepped_takes_its_own_file(tmp_path):
    """The computer's clock ran 2 min slow in the first run and NTP stepped it forward before
    the resume (wall time +120 s against the clock since boot): the connect was dated 2 min
    late, the resumed pulse's own file looked shot 2 min before it and was refused with every
    file after it, and the run stopped blaming the camera's clock. The clock since boot of the
    same boot shows the step, which is taken off: the file is the image, with no notice."""
    frame = _resumed_after(tmp_path, wall_step_s=+120.0).capture(0.1)
    assert frame.metadata["watched_file"].endswith("IMG_0002.DNG"), frame.metadata
    assert not frame.metadata.get("stray_files") and not frame.metadata.get("notices")


def test_a_resume_on_another_computer_2_min_ahead_takes_its_first_file_within_10_min(tmp_path):
    """Resumed on another computer whose clock is 2 min ahead: nothing measures how far its
    wall clock is from the first run's, which had every good file refused as shot before the
    connect. The first file is checked against this computer's clock within 10 min only:
    taken, saying so; the next is checked against it."""
    cam = _resumed_after(tmp_path, wall_step_s=+120.0, computer_after="other-computer")
    first = cam.capture(0.1)
    assert first.metadata["watched_file"].endswith("IMG_0002.DNG"), first.metadata
    said = " ".join(first.metadata.get("notices") or [])
    assert "another computer" in said and "only to within 10 min" in said, said
    second = cam.capture(0.1)
    assert second.metadata["watched_file"].endswith("IMG_0003.DNG")
    assert not second.metadata.get("notices")


def _late_file_after_a_next_day_resume(
    tmp_path, computer_after, boot_s=None, after_s=16 * 3600.0, wall_step_s=0.0
):
    """The owner stops the run (Ctrl-C) while pulse 2's file is on its way and resumes 16 h
    later (``after_s``: the computer off overnight, or asleep); the stopped run's file reaches
    the folder only after the resume connects (a Wi-Fi camera's upload queue draining), 2 s
    before the resumed pulse's own file. The resume runs on ``computer_after`` (another boot id
    after a restart), its clock since boot showing ``boot_s`` since pulse 2 (a restart starts
    it again; a sleep it does not count leaves it short; None: all of it), its wall clock
    moved ``wall_step_s``. The first image after the resume."""
    session, tether = tmp_path / "session", tmp_path / "tether"
    tether.mkdir()
    body = _Body(tether, [1.0, after_s + 30.0, 4.0], offset_s=0.0)
    camera = _ComputerClocks(body, 15.0, session)
    first = camera("this-computer")
    first.capture(0.1)
    first.expose(0.1)
    first.close()  # Ctrl-C while its file is awaited
    body.clock.sleep(body.pulses[1] + after_s + 28.0 - body.clock.now())
    camera.lost_s = 0.0 if boot_s is None else body.clock.now() - body.pulses[1] - boot_s
    camera.step_s = wall_step_s
    return camera(computer_after).capture(0.1)


def test_a_late_file_after_a_restart_and_a_next_day_resume_is_set_aside(tmp_path):
    """After a restart (on Linux a new boot id) the clock since boot cannot date the connect:
    the first file was said unchecked and the stopped run's late file, 16 h old, became the
    resumed light's image. It is now checked against this computer's wall clock within
    10 min: set aside, and the resumed pulse's own file taken, saying how far it was checked."""
    frame = _late_file_after_a_next_day_resume(tmp_path, "this-computer-rebooted", 60.0)
    assert frame.metadata["watched_file"].endswith("IMG_0003.DNG"), frame.metadata
    assert frame.metadata["stray_files"] == ["IMG_0002.DNG"], frame.metadata
    said = " ".join(frame.metadata.get("notices") or [])
    assert "IMG_0002.DNG" in said and "shot before this run connected" in said, said
    assert "only to within 10 min" in said, said


def test_a_sleep_the_clock_since_boot_did_not_count_does_not_pass_a_late_file(tmp_path):
    """Same computer and boot, but a clock since boot that stopped during a 16 h sleep (as
    ``time.monotonic`` does on macOS): it showed 0.5 s since pulse 2, the wall clock seemed set
    forward 16 h and was taken back, the connect was dated just after the Ctrl-C, and the
    stopped run's late file passed. A wall clock moved more than 10 min ahead of the clock
    since boot is not corrected by it: the wall clock dates the connect, and the file is set
    aside."""
    frame = _late_file_after_a_next_day_resume(tmp_path, "this-computer", 0.5)
    assert frame.metadata["watched_file"].endswith("IMG_0003.DNG"), frame.metadata
    assert frame.metadata["stray_files"] == ["IMG_0002.DNG"], frame.metadata


def test_a_clock_stepped_back_over_10_min_is_still_measured_by_the_clock_since_boot(tmp_path):
    """The computer's clock ran an hour fast and NTP stepped it back between a Ctrl-C and a
    resume a minute later. Only a step forward can be a sleep the clock since boot did not
    count; a step back dated by the wall clock alone would make the stopped run's late file
    look an hour younger and pass. It is measured and taken off: the file is set aside."""
    frame = _late_file_after_a_next_day_resume(
        tmp_path, "this-computer", after_s=60.0, wall_step_s=-3600.0
    )
    assert frame.metadata["watched_file"].endswith("IMG_0003.DNG"), frame.metadata
    assert frame.metadata["stray_files"] == ["IMG_0002.DNG"], frame.metadata
    assert "only to within" not in " ".join(frame.metadata.get("notices") or [])


def test_the_clock_since_boot_counts_a_sleep_where_the_system_can_and_survives_a_refusal(
    monkeypatch,
):
    """macOS's ``time.monotonic`` stops during sleep; its CLOCK_MONOTONIC counts it (Apple's
    clock_gettime(3)). A clock_gettime the system refuses (an old kernel, a sandbox) raised
    out of the connect; it falls back to ``time.monotonic``."""
    import time

    from rti_rig.drivers.cameras import folder_watch

    asked = []

    def clock_gettime(which):
        asked.append(which)
        return 7.0

    monkeypatch.setattr(folder_watch.time, "clock_gettime", clock_gettime)
    monkeypatch.setattr(folder_watch.time, "CLOCK_MONOTONIC", 6, raising=False)
    monkeypatch.setattr(folder_watch.sys, "platform", "darwin")
    assert folder_watch.since_boot() == 7.0 and asked == [6]

    def refused(which):
        raise OSError(22, "Invalid argument")

    monkeypatch.setattr(folder_watch.time, "clock_gettime", refused)
    monkeypatch.setattr(folder_watch.time, "monotonic", lambda: 42.0)
    monkeypatch.setattr(folder_watch.sys, "platform", "linux")
    monkeypatch.setattr(time, "CLOCK_BOOTTIME", 7, raising=False)
    assert folder_watch.since_boot() == 42.0


def test_a_tiff_that_can_never_be_read_is_not_waited_for_as_one_being_written(tmp_path):
    """Any tifffile error was taken as a TIFF still being written: a file named .tif that is
    no TIFF (its first bytes written, no TIFF's) cost timeout_s before its capture time was
    given up. It is now final at once; a TIFF cut short (its header there) is still waited
    for."""
    import tifffile

    from rti_rig.drivers.cameras.folder_watch import _read_capture_time

    junk = tmp_path / "junk.tif"
    junk.write_bytes(b"JFIF this is a JPEG saved as .tif" * 4)
    assert _read_capture_time(junk) == (True, None)
    whole = tmp_path / "whole.tif"
    tifffile.imwrite(whole, np.zeros((64, 64), np.uint16))
    half = tmp_path / "half.tif"
    half.write_bytes(whole.read_bytes()[:16])
    assert _read_capture_time(half) == (False, None)
    zeros = tmp_path / "zeros.tif"
    zeros.write_bytes(bytes(4096))  # a network share sets the size first, fills it later
    assert _read_capture_time(zeros) == (False, None)
    assert _read_capture_time(whole) == (True, None)  # whole, no EXIF DateTimeOriginal


def test_a_clock_set_back_onto_no_pulse_of_the_run_is_said_as_such(tmp_path):
    """Pulses 1 and 2 are 20 s apart; before pulse 3 the camera's clock is set back 12 s (less
    than the time since the first image): pulse 3's file is shot, by the clock the last image
    anchored, between pulses 1 and 2, at no pulse of the run. It is rightly not taken, but it
    was called "a late file of an earlier pulse?": no pulse was shot then."""
    body = _Body(tmp_path, [1.0, 1.0, 1.0])
    settings = FolderWatchSettings(
        folder=tmp_path, timeout_s=5.0, poll_interval_s=0.125, shutter_lag_s=0.25
    )
    cam = FolderWatchCamera(settings, clock=body.clock, trigger=body.pulse)
    cam.connect()
    cam.capture(0.5)
    body.clock.sleep(20.0)
    cam.capture(0.5)
    body.offset_s -= 12.0
    with pytest.raises(CaptureError) as stop:
        cam.capture(0.5)
    said = stop.value.message
    assert said.startswith("IMG_0003.DNG came after the pulse but was set aside"), said
    assert "late file of an earlier pulse" not in said, said
    assert "IMG_0003.DNG was shot 12 s before this pulse" in said, said
    assert "at no pulse of this run, so it is no late file of one" in said, said
    assert "the camera's clock was set back by about 12 s" in said, said
