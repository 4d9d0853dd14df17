"""Folder-watch backend: waits for the next file on an injected clock, with a timeout."""

from __future__ import annotations

import io
import json
import struct
import time

import cv2
import numpy as np
import pytest
import tifffile
from PIL import Image
from scripted_clock import ScriptedClock

from rti_rig.core.clock import SystemClock, VirtualClock
from rti_rig.core.devices import Camera
from rti_rig.core.errors import CaptureError, DeviceError
from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic, write_dng
from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
from rti_rig.drivers.cameras.settings import FolderWatchSettings


def dng(path, level=0.3, exposure_s=0.5):
    mosaic = linear_to_mosaic(np.full((32, 32), level), "RGGB", 256, 4095)
    return write_dng(
        path, mosaic, black_level=256, white_level=4095, exposure_s=exposure_s, iso=100
    )


def watch(tmp_path, clock, **kw):
    return FolderWatchCamera(FolderWatchSettings(folder=tmp_path, **kw), clock=clock)


def test_timeout_without_real_waiting(tmp_path):
    clock = VirtualClock()
    cam = watch(tmp_path, clock, timeout_s=10.0, poll_interval_s=0.5)
    assert isinstance(cam, Camera)
    cam.connect()
    t0 = time.monotonic()
    with pytest.raises(CaptureError, match=r"no new file matching .* within 10 s"):
        cam.capture(0.5)
    assert time.monotonic() - t0 < 1.0
    assert clock.now() == pytest.approx(10.0)


def test_a_timeout_names_the_new_files_no_pattern_matches(tmp_path):
    """A camera saving ``_DSC0001.ARW`` into a folder watched for ``*.CR2`` (the guide's
    example), or ``IMG_0001.CR2`` for ``*.cr2``: the timeout had asked "is the camera firing
    and saving there?" while it was doing just that."""
    (tmp_path / "notes.txt").write_text("here before the session")
    clock = ScriptedClock({0.5: lambda: dng(tmp_path / "_DSC0001.ARW")})
    cam = watch(tmp_path, clock, patterns=("*.CR2", "*.cr2"), timeout_s=2.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "_DSC0001.ARW came into the folder but no pattern matches it" in said
    assert "'*.ARW'" in said and "patterns in [camera.device]" in said
    assert "notes.txt" not in said and "is the camera firing" not in said
    # nothing came at all: the question stands
    empty = tmp_path / "empty"
    empty.mkdir()
    cam = watch(empty, VirtualClock(), patterns=("*.CR2",), timeout_s=1.0)
    cam.connect()
    with pytest.raises(CaptureError, match="is the camera firing and saving there"):
        cam.capture(0.5)


def test_timeout_on_the_system_clock_is_bounded(tmp_path):
    cam = watch(tmp_path, SystemClock(), timeout_s=0.2, poll_interval_s=0.02)
    cam.connect()
    t0 = time.monotonic()
    with pytest.raises(CaptureError, match=r"within 0\.2 s"):
        cam.capture(0.5)
    assert 0.19 <= time.monotonic() - t0 < 1.0


def test_file_that_appears_later_is_decoded_and_existing_files_ignored(tmp_path):
    dng(tmp_path / "old.dng", level=0.9)  # present before connect: not ours
    clock = ScriptedClock({1.0: lambda: dng(tmp_path / "IMG_0002.dng", level=0.3)})
    triggered: list[float] = []
    cam = FolderWatchCamera(
        FolderWatchSettings(folder=tmp_path, timeout_s=5.0, poll_interval_s=0.25),
        clock=clock,
        trigger=triggered.append,
    )
    cam.connect()
    f = cam.capture(0.5)
    assert triggered == [0.5]
    assert f.metadata["source_file"] == str(tmp_path / "IMG_0002.dng")
    assert np.mean(f.pixels) / f.white_level == pytest.approx(0.3, abs=1e-3)
    assert f.exposure_s == pytest.approx(0.5) and f.gain == 100.0
    assert f.metadata["exposure_source"] == "file"
    json.dumps(f.metadata)  # goes into the session manifest as is
    assert 1.0 <= clock.now() <= 1.5  # picked up within a poll or two of appearing
    assert f.timestamp_s == 0.0 and f.metadata["capture_finished_s"] == clock.now()
    with pytest.raises(CaptureError, match="within"):
        cam.capture(0.5)  # each file is used once


def test_file_still_growing_is_not_taken(tmp_path):
    target = tmp_path / "IMG.dng"
    data = dng(tmp_path / "full.bin").read_bytes()
    (tmp_path / "full.bin").unlink()
    # binary-exact times (multiples of 1/8 s) so virtual time never drifts past an action
    clock = ScriptedClock(
        {
            0.25: lambda: target.write_bytes(data[:100]),
            0.5: lambda: target.write_bytes(data[:2000]),
            0.75: lambda: target.write_bytes(data),
        }
    )
    cam = watch(tmp_path, clock, timeout_s=5.0, poll_interval_s=0.125, stable_polls=3)
    cam.connect()
    f = cam.capture(0.5)
    assert f.pixels.shape == (32, 32, 3)  # colour by default
    assert clock.now() == 1.0  # seen at 0.75, 0.875, 1.0: three equal sizes


def test_growing_file_at_timeout_is_reported(tmp_path):
    target = tmp_path / "IMG.dng"
    grow = {0.125 * i: (lambda i=i: target.write_bytes(b"x" * (i * 10))) for i in range(1, 40)}
    cam = watch(tmp_path, ScriptedClock(grow), timeout_s=2.0, poll_interval_s=0.125)
    cam.connect()
    with pytest.raises(CaptureError, match="still being written"):
        cam.capture(0.5)


def test_exposure_mismatch_is_refused(tmp_path):
    clock = ScriptedClock({0.1: lambda: dng(tmp_path / "a.dng", exposure_s=1 / 30)})
    cam = watch(tmp_path, clock)
    cam.connect()
    with pytest.raises(CaptureError, match="manual"):
        cam.capture(0.5)


def test_16bit_tiff_accepted_8bit_refused(tmp_path):
    def tif16():
        tifffile.imwrite(tmp_path / "a.tif", np.full((4, 4), 30000, np.uint16))

    def tif8():
        tifffile.imwrite(tmp_path / "b.tif", np.full((4, 4), 200, np.uint8))

    clock = ScriptedClock({0.1: tif16, 0.5: tif8})
    cam = watch(tmp_path, clock, patterns=("*.tif",))
    cam.connect()
    f = cam.capture(0.5)
    assert np.all(f.pixels == 30000) and f.exposure_s == 0.5
    assert f.metadata["exposure_source"] == "requested"
    with pytest.raises(CaptureError, match="8-bit"):
        cam.capture(0.5)


def test_a_tiff_cut_short_is_a_named_capture_error(tmp_path):
    """Half a TIFF (a copy cut short, a writer that paused longer than the stability polls):
    tifffile's ValueError had escaped the camera as itself, a traceback from 'rti-rig run'."""
    whole = tmp_path / "whole.tif.tmp"
    tifffile.imwrite(whole, np.full((64, 64, 3), 30000, np.uint16), photometric="rgb")
    data = whole.read_bytes()
    whole.unlink()

    def half():
        (tmp_path / "a.tif").write_bytes(data[: len(data) // 2])

    cam = watch(tmp_path, ScriptedClock({0.1: half}), patterns=("*.tif",))
    cam.connect()
    with pytest.raises(CaptureError, match=r"a\.tif.*complete TIFF"):
        cam.capture(0.5)


@pytest.mark.parametrize("suffix", [".tif", ".png"])
def test_colour_file_arrives_in_rgb_order(tmp_path, suffix):
    """A red 16-bit file is red in the frame, whatever library decodes it: tifffile hands over
    RGB as stored, OpenCV BGR (the TIFF path had been reversed as if it were OpenCV's, so a
    watched folder of TIFFs gave a session with red and blue swapped)."""
    rgb = np.zeros((4, 6, 3), np.uint16)
    rgb[..., 0], rgb[..., 2] = 50000, 1000

    def write():
        import cv2

        path = tmp_path / f"IMG_0001{suffix}"
        if suffix == ".tif":
            tifffile.imwrite(path, rgb, photometric="rgb")
        else:
            assert cv2.imwrite(str(path), rgb[..., ::-1])  # OpenCV writes BGR arrays

    cam = watch(tmp_path, ScriptedClock({0.1: write}), patterns=(f"*{suffix}",))
    cam.connect()
    f = cam.capture(0.5)
    assert f.pixels.shape == (4, 6, 3)
    assert np.all(f.pixels[..., 0] == 50000) and np.all(f.pixels[..., 2] == 1000)


def test_missing_folder_and_not_connected(tmp_path):
    with pytest.raises(DeviceError, match="does not exist"):
        watch(tmp_path / "nope", VirtualClock()).connect()
    with pytest.raises(CaptureError, match="not connected"):
        watch(tmp_path, VirtualClock()).capture(0.5)


def test_trigger_whose_confirmation_is_lost_waits_for_the_file(tmp_path):
    from rti_rig.drivers.cameras.folder_watch import TriggerUnconfirmed

    fired = []

    def trigger(exposure_s):
        fired.append(exposure_s)
        dng(tmp_path / "IMG_0001.dng")  # the camera did fire
        raise TriggerUnconfirmed("dome: no reply within 0.5 s")

    cam = FolderWatchCamera(
        FolderWatchSettings(folder=tmp_path), clock=VirtualClock(), trigger=trigger
    )
    cam.connect()
    f = cam.capture(0.5)
    assert fired == [0.5]  # sent once, never resent
    assert f.metadata["trigger_unconfirmed"] == "dome: no reply within 0.5 s"
    assert any("confirmation was lost" in n for n in f.metadata["notices"])


def test_trigger_unconfirmed_and_no_file_is_an_error_naming_both(tmp_path):
    from rti_rig.drivers.cameras.folder_watch import TriggerUnconfirmed

    def trigger(exposure_s):
        raise TriggerUnconfirmed("dome: no reply within 0.5 s")

    cam = FolderWatchCamera(
        FolderWatchSettings(folder=tmp_path, timeout_s=1.0), clock=VirtualClock(), trigger=trigger
    )
    cam.connect()
    with pytest.raises(CaptureError, match=r"no new file.*not confirmed either.*no reply"):
        cam.capture(0.5)


def test_a_triggered_exposure_ends_shutter_lag_plus_exposure_after_the_pulse(tmp_path):
    """With the dome's release line, the exposure is over ``shutter_lag_s`` + exposure after
    the pulse: ``expose`` says so without waiting for the file, which ``collect`` awaits (it
    may take seconds over Wi-Fi; the LED need not stay on for that)."""
    from rti_rig.core.devices import ExposingCamera

    clock = ScriptedClock({4.0: lambda: dng(tmp_path / "IMG_0001.dng")})  # the file comes late
    fired: list[float] = []
    cam = FolderWatchCamera(
        FolderWatchSettings(folder=tmp_path, shutter_lag_s=0.3),
        clock=clock,
        trigger=lambda e: fired.append(clock.now()),
    )
    assert isinstance(cam, ExposingCamera)
    cam.connect()
    ended = cam.expose(0.5)
    assert len(fired) == 1 and ended == pytest.approx(fired[0] + 0.3 + 0.5)
    f = cam.collect()
    assert f.metadata["source_file"].endswith("IMG_0001.dng")
    assert clock.now() >= 4.0 > ended + 2.0


def test_an_untriggered_exposure_is_over_once_its_file_has_come(tmp_path):
    """Someone else fires the camera: only the file's arrival says the exposure is over."""
    clock = ScriptedClock({2.0: lambda: dng(tmp_path / "IMG_0001.dng")})
    cam = watch(tmp_path, clock)
    cam.connect()
    ended = cam.expose(0.5)
    assert ended is not None and ended >= 2.0
    assert cam.collect().metadata["source_file"].endswith("IMG_0001.dng")


def test_a_whole_file_libraw_does_not_read_is_said_at_once_naming_it(tmp_path):
    """A tethering program saving a RAW in a format LibRaw does not read (a body newer than
    it): the file is whole and will never decode. The camera had waited ``timeout_s`` for it
    to change and then advised raising stable_polls or poll_interval_s."""
    clock = ScriptedClock(
        {
            0.5: lambda: (tmp_path / "IMG_0001.CR2").write_bytes(
                b"\x89NEWRAW" + bytes(range(256)) * 64
            )
        }
    )
    cam = watch(tmp_path, clock, patterns=("*.CR2",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0001.CR2" in said and "does not read this file's format" in said
    assert "pip install -U rawpy" in said and str(tmp_path) in said
    assert "waiting will not help" in said and "stable_polls or poll_interval_s" not in said
    assert clock.now() < 5.0  # not the 30 s timeout
    assert (tmp_path / "IMG_0001.CR2").exists()  # left where the program saved it


def test_a_raw_refusal_names_the_folders_file_and_leaves_libraws_words_as_said(
    tmp_path, monkeypatch
):
    """A RAW LibRaw refuses, decoded from the session's copy: the stop names the folder's
    file, then LibRaw's error kind and its own words, unaltered (LibRaw's data errors name
    the file it read, the copy). The copy's path had been replaced by string substitution in
    the whole message, LibRaw's words included, which then named a file LibRaw never read."""
    import rawpy

    folder = tmp_path / "tether"
    folder.mkdir()
    incoming = tmp_path / "s" / "raw" / ".incoming"
    copy = incoming / "IMG_0001.CR2"

    def refuses(path, *args, **kwargs):  # type: ignore[no-untyped-def]
        raise rawpy.LibRawDataError(f"{path}: data corrupted at 1234".encode())

    monkeypatch.setattr(rawpy, "imread", refuses)
    clock = ScriptedClock({0.5: lambda: (folder / "IMG_0001.CR2").write_bytes(b"II*\x00" * 512)})
    cam = watch(folder, clock, patterns=("*.CR2",), timeout_s=5.0, poll_interval_s=0.25)
    cam.output_dir = incoming
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert (
        f"{folder / 'IMG_0001.CR2'}: LibRaw cannot decode this file (LibRawDataError: "
        f"{copy}: data corrupted at 1234); is it a complete RAW/DNG download?"
    ) in said, said
    assert "b'" not in said, said


def test_a_file_sized_before_it_is_written_is_waited_for(tmp_path):
    """A program copying onto a network share may set the file's full size first (zeros) and
    fill it afterwards: LibRaw reads the zeros as no known format, but the file is not whole
    yet, so it is waited for and decoded once written."""
    whole = tmp_path / "whole.dng"
    dng(whole, level=0.3)
    data = whole.read_bytes()
    whole.unlink()
    target = tmp_path / "shots"
    target.mkdir()
    clock = ScriptedClock(
        {
            0.5: lambda: (target / "IMG_0001.dng").write_bytes(bytes(len(data))),
            3.0: lambda: (target / "IMG_0001.dng").write_bytes(data),
        }
    )
    cam = watch(target, clock, timeout_s=10.0, poll_interval_s=0.25)
    cam.connect()
    frame = cam.capture(0.5)
    assert frame.metadata["originals"][0]["name"] == "IMG_0001.dng"
    assert frame.pixels.mean() > 0


def test_a_file_moved_away_before_it_is_copied_is_named_with_what_to_do(tmp_path):
    """Bound to a session, a taken file is copied in before it is decoded; one another program
    moved out of the folder first (an auto import) is said as such, not as a disk failure."""
    watched, incoming = tmp_path / "w", tmp_path / "s" / "raw" / ".incoming"
    watched.mkdir()
    cam = watch(watched, VirtualClock(), timeout_s=5.0)
    cam.output_dir = incoming
    cam.connect()
    dng(watched / "IMG_0001.dng")
    path = cam.wait_for_file()
    path.rename(tmp_path / "IMG_0001.dng")  # imported elsewhere
    with pytest.raises(CaptureError) as info:
        cam._decode_complete(path, 0.5, 0.0)
    said = str(info.value)
    assert "IMG_0001.dng came into" in said and "moved or deleted before rti-rig" in said
    assert "no image was recorded for this light" in said
    assert not list(incoming.iterdir())


def test_a_folder_that_went_away_is_said_at_the_timeout(tmp_path):
    """The watched folder on a network share that disconnects mid-session: the timeout had
    asked "is the camera firing and saving there?" of a camera that was."""
    share = tmp_path / "share"
    share.mkdir()
    clock = ScriptedClock({0.5: lambda: share.rmdir()})
    cam = watch(share, clock, timeout_s=3.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert str(share) in said and "no longer there or cannot be reached" in said
    assert "network share" in said and "--resume" in said
    assert "is the camera firing" not in said


def test_a_raw_plus_jpeg_camera_whose_jpeg_comes_first_is_told_to_match_the_raw(tmp_path):
    """Patterns matching a RAW+JPEG camera's two files, its JPEG whole before its RAW appears:
    the JPEG is taken (8-bit), and the refusal had said "save RAW or 16-bit TIFF" to an owner
    whose camera saves RAW; it now says to match only the RAW, naming the patterns."""
    import cv2

    clock = ScriptedClock(
        {
            0.5: lambda: cv2.imwrite(
                str(tmp_path / "IMG_0001.JPG"), np.full((32, 32, 3), 100, np.uint8)
            ),
            1.0: lambda: dng(tmp_path / "IMG_0001.CR2"),
        }
    )
    cam = watch(tmp_path, clock, patterns=("*.CR2", "*.JPG"))
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0001.JPG is 8-bit" in said and "match only the RAW" in said
    assert "keep ['*.CR2'] in patterns" in said and "save RAW" not in said
    # a folder watched for JPEGs alone: the advice stands
    only = tmp_path / "jpeg"
    only.mkdir()
    clock = ScriptedClock(
        {0.5: lambda: cv2.imwrite(str(only / "a.jpg"), np.full((32, 32, 3), 9, np.uint8))}
    )
    cam = watch(only, clock, patterns=("*.jpg",))
    cam.connect()
    with pytest.raises(CaptureError, match="save RAW or 16-bit TIFF"):
        cam.capture(0.5)


def test_a_jpeg_whose_raw_is_late_is_not_advised_as_a_pattern_to_add(tmp_path):
    """A RAW+JPEG camera watched for its RAW alone, the RAW late at the timeout: the timeout
    had advised adding '*.JPG' to patterns (whose 8-bit data is refused as an image); it now
    says the RAW has not come, to raise timeout_s or set the camera to save RAW."""
    import cv2

    def jpeg(name):
        cv2.imwrite(str(tmp_path / name), np.full((8, 8, 3), 9, np.uint8))

    clock = ScriptedClock({0.5: lambda: jpeg("IMG_0001.JPG")})
    cam = watch(tmp_path, clock, patterns=("*.CR2",), timeout_s=2.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0001.JPG came into the folder but not its RAW" in said
    assert "raise timeout_s" in said and "'*.JPG'" not in said
    assert "add its pattern (e.g." not in said
    # its RAW came under a name no pattern matches (a case mismatch): that RAW's pattern is said
    other = tmp_path / "case"
    other.mkdir()
    clock = ScriptedClock({0.5: lambda: (jpeg("case/IMG_0002.JPG"), dng(other / "IMG_0002.cr2"))})
    cam = watch(other, clock, patterns=("*.CR2",), timeout_s=2.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0002.cr2 came into the folder but no pattern matches it" in said
    assert "'*.cr2'" in said and "'*.JPG'" not in said and "not its RAW" not in said


def test_a_file_named_tif_that_is_no_tiff_is_said_at_once_naming_it(tmp_path):
    """A file saved under a .tif name whose first bytes are written and are no TIFF header (a
    damaged file, a JPEG saved as .tif): its capture-time read gave it up at once, but its
    decode still waited ``timeout_s`` for it to change and then advised raising stable_polls
    or poll_interval_s. It is now said at once, naming the file and where it is left."""
    clock = ScriptedClock(
        {0.5: lambda: (tmp_path / "IMG_0001.tif").write_bytes(b"JFIF not a TIFF" * 64)}
    )
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0001.tif is no TIFF" in said and "waiting will not help" in said, said
    # worded by the camera from the reader's fields: the file's name and the reader's reason
    assert f"cannot read image file {tmp_path / 'IMG_0001.tif'} (" in said, said
    assert "complete TIFF" not in said, said
    assert str(tmp_path) in said and "stable_polls or poll_interval_s" not in said, said
    assert clock.now() < 5.0  # the virtual clock: not the 30 s timeout
    assert (tmp_path / "IMG_0001.tif").exists()  # left where the program saved it


def _tiff_bytes(tmp_path, compression=None, pixels=None) -> tuple[bytes, int, int]:
    """A whole 16-bit RGB TIFF's bytes (of ``pixels``, all 30000 unless given), and its first
    strip's offset and byte count."""
    whole = tmp_path / "whole.tif.tmp"
    if pixels is None:
        pixels = np.full((64, 64, 3), 30000, np.uint16)
    tifffile.imwrite(whole, pixels, photometric="rgb", compression=compression)
    with tifffile.TiffFile(whole) as tif:
        offset, count = tif.pages[0].dataoffsets[0], tif.pages[0].databytecounts[0]
    data = whole.read_bytes()
    whole.unlink()
    return data, offset, count


def test_a_whole_tiff_whose_data_will_not_decode_is_said_at_once_naming_it(tmp_path):
    """A TIFF whose header and structure are all written, its size steady, but whose
    compressed data is damaged (a copy gone wrong): its decode waited ``timeout_s`` for it to
    change, then advised raising stable_polls or poll_interval_s. Nothing more is coming: it
    is said at once, naming the file, where it is left and what to do."""
    data, offset, count = _tiff_bytes(tmp_path, compression="zlib")
    damaged = data[:offset] + bytes(b ^ 0x5A for b in data[offset : offset + count])
    damaged += data[offset + count :]
    clock = ScriptedClock({0.5: lambda: (tmp_path / "IMG_0001.tif").write_bytes(damaged)})
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert f"cannot read image file {tmp_path / 'IMG_0001.tif'} (" in said, said
    assert "IMG_0001.tif is a damaged TIFF" in said and "waiting will not help" in said, said
    assert f"left in {tmp_path}" in said and "Save the shot again" in said, said
    assert "stable_polls or poll_interval_s" not in said and ".incoming" not in said, said
    assert clock.now() < 5.0  # the virtual clock: not the 30 s timeout
    assert (tmp_path / "IMG_0001.tif").exists()


def test_a_tiff_whose_writer_pauses_mid_file_is_decoded_once_whole(tmp_path):
    """Half a TIFF whose structure names data past its end is not called damaged: its writer
    may have paused (a network share, a Wi-Fi upload) longer than the stability polls, and
    the rest, when it comes, makes it whole."""
    data, _, _ = _tiff_bytes(tmp_path, compression="zlib")
    target = tmp_path / "IMG_0001.tif"
    clock = ScriptedClock(
        {
            0.5: lambda: target.write_bytes(data[: len(data) - 40]),
            4.0: lambda: target.write_bytes(data),
        }
    )
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    frame = cam.capture(0.5)
    assert np.all(frame.pixels == 30000)
    assert clock.now() >= 4.0


def test_a_tiff_whose_end_is_not_filled_yet_is_waited_for(tmp_path):
    """A share that sets a file's full size first and fills it later: its header and
    structure are there, its data still zeros; it is not called damaged, and is decoded once
    filled."""
    data, offset, _ = _tiff_bytes(tmp_path, compression="zlib")
    target = tmp_path / "IMG_0001.tif"
    clock = ScriptedClock(
        {
            0.5: lambda: target.write_bytes(data[:offset] + bytes(len(data) - offset)),
            4.0: lambda: target.write_bytes(data),
        }
    )
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    assert np.all(cam.capture(0.5).pixels == 30000)


def test_a_tiff_whose_ifd_is_damaged_is_said_at_once_naming_it(tmp_path):
    """A TIFF whose header is written and whose IFD entries are garbage: tifffile reads it,
    logging, as an image of no pixels. It is named at once as damaged, with what to do (an
    image of no pixels had been refused naming only its shape, then waited for)."""
    data, _, _ = _tiff_bytes(tmp_path, compression="zlib")
    damaged = data[:100] + b"\xff" * 100 + data[200:]
    clock = ScriptedClock({0.5: lambda: (tmp_path / "IMG_0001.tif").write_bytes(damaged)})
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0001.tif is a damaged TIFF" in said and "name no image data" in said, said
    assert f"left in {tmp_path}" in said and "waiting will not help" in said, said
    assert "shape" not in said and "stable_polls" not in said, said
    assert clock.now() < 5.0  # the virtual clock: not the 30 s timeout


def _garbage_first_ifd(data: bytes, kind: str) -> bytes:
    """``data`` (a little-endian classic TIFF) with its first IFD garbage of ``kind``."""
    (ifd,) = struct.unpack("<I", data[4:8])
    if kind == "tag count":  # bytes XORed: a count over any writer's
        return data[:ifd] + bytes(b ^ 0x5A for b in data[ifd : ifd + 2]) + data[ifd + 2 :]
    if kind == "entry type":  # a plausible count whose IFD would run past the end
        count = struct.pack("<H", (len(data) - ifd) // 12 + 5)
        return data[:ifd] + count + data[ifd + 2 : ifd + 4] + b"\x5a\x5a" + data[ifd + 6 :]
    if kind == "zero count in the data":  # the header names a 0 0 pair inside the pixels
        at = next(
            n
            for n in range(ifd + 64, len(data) - 16, 2)
            if data[n : n + 2] == bytes(2) and all(data[n + 2 : n + 18])
        )
        return data[:4] + struct.pack("<I", at) + data[8:]
    assert kind == "inside the header"
    return data[:4] + struct.pack("<I", 2) + data[8:]


@pytest.mark.parametrize(
    "kind", ["tag count", "entry type", "inside the header", "zero count in the data"]
)
@pytest.mark.parametrize("trigger", [False, True])
def test_a_tiff_whose_first_ifd_is_garbage_is_said_at_once_naming_it(tmp_path, kind, trigger):
    """A whole TIFF, its size steady, whose header names a first IFD inside the file holding
    what no writer on its way leaves: a tag count over 4096 (tifffile: "suspicious number of
    tags"), an entry of a type no TIFF has in an IFD that would run past the end, or an
    offset inside the header. It had been waited for ``timeout_s`` (with a trigger, in its
    capture-time read and again in its decode), then advice to raise stable_polls. It is
    named at once as damaged, with where it is left and what to do."""
    data, _, _ = _tiff_bytes(tmp_path, compression="zlib")
    if kind == "zero count in the data":  # pixels holding a 0 0 pair (a black pixel's red)
        data, _, _ = _tiff_bytes(tmp_path, pixels=_PIXELS_WITH_BLACK)
    damaged = _garbage_first_ifd(data, kind)
    target = tmp_path / "IMG_0001.tif"
    clock = ScriptedClock({0.5: lambda: target.write_bytes(damaged)})
    cam = FolderWatchCamera(
        FolderWatchSettings(
            folder=tmp_path, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25
        ),
        clock=clock,
        trigger=(lambda exposure_s: None) if trigger else None,
    )
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    why = {
        "tag count": "gives a tag count of",
        "entry type": "has data type 23130, which no TIFF has",
        "inside the header": "at byte 2, inside the 8-byte header",
        "zero count in the data": "gives a tag count of 0, which no finished IFD has",
    }[kind]
    assert "IMG_0001.tif is a damaged TIFF" in said and why in said, said
    assert f"left in {tmp_path}" in said and "waiting will not help" in said, said
    assert "Save the shot again" in said, said
    assert "stable_polls" not in said and "complete TIFF" not in said, said
    assert clock.now() < 5.0  # the virtual clock: not the 30 s timeout
    assert target.read_bytes() == damaged  # left where the program saved it


def test_no_state_a_writer_leaves_a_tiff_in_reads_as_a_garbage_ifd(tmp_path):
    """Every state tifffile's and libtiff's writers, and a copy cut anywhere, leave a TIFF in
    on its way is not taken for a garbage IFD: they are waited for."""
    from rti_rig.drivers.cameras.tiff_structure import ifd_garbage

    states = []
    for kind in ("plain", "zlib", "tiled", "BigTIFF", "multi-page", "black", "black BigTIFF"):
        part, whole = _tifffile_order(kind)
        states += part + [whole[:n] for n in range(0, len(whole), 7)]
    whole = _libtiff_whole()
    states += [whole[:n] for n in range(0, len(whole), 7)]
    # Pillow's order (header, IFD, then its strips), of a shot with black pixels: each state
    # as written and cut anywhere, and each cut of a whole file filled in place by a share
    for compression in (None, "tiff_lzw", "tiff_adobe_deflate"):
        log = _WriteLog()
        Image.fromarray(_PIXELS_WITH_BLACK[..., 0]).save(
            log, format="TIFF", compression=compression
        )
        whole = log.getvalue()
        states += _as_written(log.writes) + [whole[:n] for n in range(0, len(whole), 7)]
    # tifffile's and libtiff's, of a shot with black pixels, filled in place by a share (its
    # full size set first, zeros where it has not filled)
    for whole in (_tifffile_order("plain")[1], _tifffile_order("black")[1], _libtiff_whole()):
        states += [whole[:n] + bytes(len(whole) - n) for n in range(0, len(whole), 97)]
    target = tmp_path / "IMG_0001.tif"
    for n, state in enumerate(states):
        target.write_bytes(state)
        assert ifd_garbage(target) is None, (n, len(state))


def test_a_tiff_filled_in_place_up_to_its_ifd_is_waited_for(tmp_path):
    """A share that sets a file's full size first and fills it in order, read when the fill
    has reached the middle of its IFD: tifffile reads the zero entries past, as an image of no
    pixels. Its end is still zeros: it is not called damaged, and is decoded once filled."""
    data, _, _ = _tiff_bytes(tmp_path, compression="zlib")
    target = tmp_path / "IMG_0001.tif"
    clock = ScriptedClock(
        {
            0.5: lambda: target.write_bytes(data[:40] + bytes(len(data) - 40)),
            4.0: lambda: target.write_bytes(data),
        }
    )
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    assert np.all(cam.capture(0.5).pixels == 30000)


class _WriteLog(io.BytesIO):
    """A file object that records each write a TIFF writer makes, where it makes it."""

    def __init__(self) -> None:
        super().__init__()
        self.writes: list[tuple[int, bytes]] = []

    def write(self, data) -> int:  # type: ignore[override]
        self.writes.append((self.tell(), bytes(data)))
        return super().write(data)


def _as_written(writes: list[tuple[int, bytes]]) -> list[bytes]:
    """The file as it stands after each write (a seek past the end leaves zeros, as a file
    system does): what a reader polling the folder may find."""
    buf, states = bytearray(), []
    for at, data in writes:
        buf.extend(bytes(max(0, at - len(buf))))
        buf[at : at + len(data)] = data
        states.append(bytes(buf))
    return states


_PIXELS = np.full((64, 64, 3), 30000, np.uint16)
#: a shot with one black pixel, whose red (two zero bytes) is followed by lit pixels
_PIXELS_WITH_BLACK = _PIXELS.copy()
_PIXELS_WITH_BLACK[20, 20, 0] = 0


def _tifffile_order(kind: str) -> tuple[list[bytes], bytes]:
    """tifffile's own writer order (a header naming an IFD at offset 8, that slot zeroed while
    the data goes out, then the IFD): the states short of whole, and the whole file."""
    log = _WriteLog()
    if kind == "multi-page":  # the image and a reduced preview, as a camera program saves
        with tifffile.TiffWriter(log) as tw:
            tw.write(_PIXELS, photometric="rgb")
            tw.write(_PIXELS[::4, ::4], photometric="rgb", subfiletype=1)
    else:
        options = {
            "plain": {},
            "zlib": {"compression": "zlib"},
            "tiled": {"tile": (32, 32)},
            "BigTIFF": {"bigtiff": True},
            "black": {},
            "black BigTIFF": {"bigtiff": True},
        }[kind]
        pixels = _PIXELS_WITH_BLACK if kind.startswith("black") else _PIXELS
        tifffile.imwrite(log, pixels, photometric="rgb", **options)
    whole = log.getvalue()
    states = _as_written(log.writes)
    assert states[-1] == whole
    return [x for x in states if x != whole], whole


def _capture_growing(folder, part: bytes, whole: bytes):
    """Capture a frame whose file holds ``part`` at t=0.5 and ``whole`` at t=4.0."""
    folder.mkdir()
    target = folder / "IMG_0001.tif"
    clock = ScriptedClock(
        {0.5: lambda: target.write_bytes(part), 4.0: lambda: target.write_bytes(whole)}
    )
    cam = watch(folder, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    return cam.capture(0.5), clock


@pytest.mark.parametrize("kind", ["plain", "zlib", "tiled", "BigTIFF", "multi-page"])
def test_a_tiff_in_tifffiles_write_order_is_waited_for_and_decoded_once_whole(tmp_path, kind):
    """Each state tifffile's writer leaves a TIFF in on its way (its IFD slot zeroed while the
    data goes out, read as an image of no pixels) is a file still being written, not a
    damaged one: it is waited for and decoded once whole (it had stopped the session at once
    as 'a damaged TIFF')."""
    states, whole = _tifffile_order(kind)
    assert any(len(x) >= 16 and not any(x[8:16]) for x in states)  # the zeroed IFD slot
    for n, part in enumerate(states):
        frame, _ = _capture_growing(tmp_path / f"state{n}", part, whole)
        assert np.all(frame.pixels == 30000), (n, len(part))


def _libtiff_whole() -> bytes:
    """A whole TIFF as libtiff writes it (OpenCV's imwrite: LZW strips, the IFD last)."""
    ok, encoded = cv2.imencode(".tif", np.full((256, 320, 3), 30000, np.uint16))
    assert ok
    return encoded.tobytes()


def test_a_libtiff_tiff_copied_in_halves_is_waited_for_and_decoded_once_whole(tmp_path):
    """A copy of a libtiff TIFF (cp, rsync, SMB, a Wi-Fi upload) paused half way: its IFD,
    written last, is not there yet, and tifffile reads it as an image of no pixels. It is
    waited for and decoded once whole (it had stopped the session at once as 'a damaged
    TIFF ... its IFDs name no image data')."""
    whole = _libtiff_whole()
    frame, clock = _capture_growing(tmp_path / "w", whole[: len(whole) // 2], whole)
    assert np.all(frame.pixels == 30000)
    assert clock.now() >= 4.0


def test_a_tiff_in_libtiffs_write_order_is_waited_for_and_decoded_once_whole(tmp_path):
    """libtiff's own order: its header with a first-IFD offset of 0, the strips, the IFD,
    then the header patched. Each state before the patch is waited for, not called damaged."""
    whole = _libtiff_whole()
    (ifd,) = struct.unpack("<I", whole[4:8])
    unpatched = whole[:4] + bytes(4)
    states = [unpatched, unpatched + whole[8:ifd], unpatched + whole[8:]]
    for n, part in enumerate(states):
        frame, _ = _capture_growing(tmp_path / f"state{n}", part, whole)
        assert np.all(frame.pixels == 30000), (n, len(part))


@pytest.mark.parametrize("bigtiff", [False, True])
def test_a_tiff_cut_within_its_header_is_waited_for_not_a_traceback(tmp_path, bigtiff):
    """A TIFF of which only its first 2 to 15 bytes are written: tifffile's header unpack
    had escaped the capture as 'struct.error: unpack requires a buffer of 4 bytes'. It is a
    file still being written: waited for, and decoded once whole. A header only (8 bytes of
    a classic TIFF) is too."""
    log = _WriteLog()
    tifffile.imwrite(log, _PIXELS, photometric="rgb", bigtiff=bigtiff)
    whole = log.getvalue()
    for n in range(2, 16):
        frame, clock = _capture_growing(tmp_path / f"cut{n}", whole[:n], whole)
        assert np.all(frame.pixels == 30000), n
        assert clock.now() >= 4.0, n


def test_a_png_frame_is_decoded_once(tmp_path, monkeypatch):
    """A PNG (or JPEG) frame is decoded by OpenCV once (a leftover second imread had decoded
    each frame twice)."""
    cv2.imwrite(str(tmp_path / "whole.png"), np.full((32, 32, 3), 30000, np.uint16))
    decodes = []
    imread = cv2.imread

    def counting(*args, **kwargs):
        decodes.append(args[0])
        return imread(*args, **kwargs)

    monkeypatch.setattr(cv2, "imread", counting)
    clock = ScriptedClock({0.5: lambda: (tmp_path / "whole.png").rename(tmp_path / "IMG_0001.png")})
    cam = watch(tmp_path, clock, patterns=("IMG_*.png",), timeout_s=10.0, poll_interval_s=0.25)
    cam.connect()
    assert np.all(cam.capture(0.5).pixels == 30000)
    assert len(decodes) == 1, decodes


def _with_compression_tag(data: bytes, code: int) -> bytes:
    """``data`` (a little-endian classic TIFF) with its Compression tag set to ``code``."""
    out = bytearray(data)
    (ifd,) = struct.unpack("<I", out[4:8])
    (count,) = struct.unpack("<H", out[ifd : ifd + 2])
    for n in range(count):
        entry = ifd + 2 + 12 * n
        if struct.unpack("<H", out[entry : entry + 2])[0] == 259:
            out[entry + 8 : entry + 10] = struct.pack("<H", code)
            return bytes(out)
    raise AssertionError("no Compression tag")


def test_a_tiff_in_a_compression_the_reader_does_not_decode_is_named_with_what_to_save_in(
    tmp_path,
):
    """A whole TIFF whose Compression tag names one the reader does not decode (65000,
    EER_V0) had been called damaged, with advice to check the disk or share. The compression
    is named, with the compressions to save in, at once."""
    data, _, _ = _tiff_bytes(tmp_path)
    odd = _with_compression_tag(data, 65000)
    clock = ScriptedClock({0.5: lambda: (tmp_path / "IMG_0001.tif").write_bytes(odd)})
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "compressed as EER_V0 (TIFF compression 65000)" in said, said
    assert "uncompressed, or with LZW or Deflate (zlib) compression" in said, said
    assert "damaged" not in said and "check the disk" not in said, said
    assert f"left in {tmp_path}" in said and "waiting will not help" in said, said
    assert clock.now() < 5.0  # the virtual clock: not the 30 s timeout


@pytest.mark.parametrize("compression", [None, "lzw", "zlib"])
def test_the_compressions_advised_are_ones_the_reader_decodes(tmp_path, compression):
    """What a refused compression's advice names (uncompressed, LZW, Deflate) really reads."""
    data, _, _ = _tiff_bytes(tmp_path, compression=compression)
    clock = ScriptedClock({0.5: lambda: (tmp_path / "IMG_0001.tif").write_bytes(data)})
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    assert np.all(cam.capture(0.5).pixels == 30000)


@pytest.mark.parametrize("kind", [14, 15, 40])
def test_a_paused_tiff_with_a_private_tag_of_an_unlisted_type_is_waited_for(tmp_path, kind):
    """A good TIFF carrying one private tag whose data type the reader does not list (14
    UNICODE and 15 COMPLEX, which tifffile and LibRaw know; or a vendor's own), its writer
    pausing half way: the shot was called damaged ("has data type 15, which no TIFF has") and
    the session stopped. TIFF 6.0 tells readers to skip such a field, and tifffile reads the
    image: it is waited for and decoded whole."""
    whole = tmp_path / "whole.tif.tmp"
    tifffile.imwrite(
        whole,
        np.full((64, 64, 3), 30000, np.uint16),
        photometric="rgb",
        extratags=[(65000, "H", 1, 7, True)],
    )
    data = bytearray(whole.read_bytes())
    whole.unlink()
    (ifd,) = struct.unpack_from("<I", data, 4)
    (count,) = struct.unpack_from("<H", data, ifd)
    entry = next(
        ifd + 2 + 12 * n
        for n in range(count)
        if struct.unpack_from("<H", data, ifd + 2 + 12 * n)[0] == 65000
    )
    struct.pack_into("<H", data, entry + 2, kind)
    data = bytes(data)
    assert ifd + 2 + 12 * count < len(data) // 2  # the whole IFD is in the half written first
    target = tmp_path / "IMG_0001.tif"
    clock = ScriptedClock(
        {
            0.5: lambda: target.write_bytes(data[: len(data) // 2]),
            3.0: lambda: target.write_bytes(data),
        }
    )
    cam = watch(tmp_path, clock, patterns=("*.tif",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    frame = cam.capture(0.5)
    assert frame.pixels.shape[:2] == (64, 64)
    assert clock.now() >= 3.0


def test_a_text_file_that_matches_patterns_is_said_to_be_no_image_at_once(tmp_path):
    """An XMP sidecar a raw developer writes beside each shot, matched by ``patterns =
    ["IMG_*"]``: it stopped the session after ``timeout_s`` with "did not change … raise
    stable_polls or poll_interval_s", though it is whole and no wait makes text an image."""
    xmp = '<?xpacket begin="\ufeff"?><x:xmpmeta xmlns:x="adobe:ns:meta/">é</x:xmpmeta>\n'
    clock = ScriptedClock(
        {0.5: lambda: (tmp_path / "IMG_0001.xmp").write_text(xmp * 40, encoding="utf-8")}
    )
    cam = watch(tmp_path, clock, patterns=("IMG_*",), timeout_s=30.0, poll_interval_s=0.25)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0001.xmp is a text file, not an image" in said, said
    assert "Narrow patterns in [camera.device] (now ['IMG_*'])" in said, said
    assert "stable_polls or poll_interval_s" not in said, said
    assert clock.now() < 5.0  # said at once, not after the 30 s timeout
    assert (tmp_path / "IMG_0001.xmp").exists()  # left where the program saved it
