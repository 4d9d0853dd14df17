"""A watched folder's file is decoded from the session's hidden copy (``raw/.incoming``); a
refusal met while decoding that copy names the file the user's program saved, and where it is
left, never the copy.

Found by a review: since the folder watch stopped replacing the copy's path inside every
message (LibRaw's own words included), the decoder's plain "RAW file not found: <path>" named
the hidden copy, and the driver's own refusals (a wrong exposure, 8-bit data) named the copy's
name, which differs from the folder's beside an earlier copy (``IMG_0001_2.dng``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scripted_clock import ScriptedClock

from rti_rig.core.errors import CaptureError
from rti_rig.drivers.cameras.dng_writer import linear_to_mosaic, write_dng
from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
from rti_rig.drivers.cameras.settings import FolderWatchSettings


def _dng(path: Path, exposure_s: float = 0.5) -> None:
    mosaic = linear_to_mosaic(np.full((32, 32), 0.3), "RGGB", 256, 4095)
    write_dng(path, mosaic, black_level=256, white_level=4095, exposure_s=exposure_s, iso=100)


def _bound_camera(tmp_path: Path, clock: ScriptedClock) -> tuple[FolderWatchCamera, Path]:
    """A camera watching ``tmp_path/tether``, bound to a session whose copies go to
    ``tmp_path/s/raw/.incoming`` (returned)."""
    incoming = tmp_path / "s" / "raw" / ".incoming"
    cam = FolderWatchCamera(
        FolderWatchSettings(folder=tmp_path / "tether", timeout_s=30.0, poll_interval_s=0.25),
        clock=clock,
    )
    cam.output_dir = incoming
    return cam, incoming


@pytest.mark.parametrize("folder_file_too", [False, True])
def test_a_copy_removed_before_its_decode_names_the_folders_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, folder_file_too: bool
) -> None:
    """The copy goes between its making and its decode (the right moment, by wrapping the
    driver's copy step): the stop names the folder's file and whether it is left there, at
    once (the file has not changed, so waiting for it to change would not help)."""
    folder = tmp_path / "tether"
    folder.mkdir()
    clock = ScriptedClock({0.5: lambda: _dng(folder / "IMG_0001.dng")})
    cam, incoming = _bound_camera(tmp_path, clock)
    hold = cam._hold

    def hold_then_lose(path: Path) -> Path:
        held = hold(path)
        held.unlink()  # something cleaned the session's folder
        if folder_file_too:
            path.unlink()  # and an auto import took the folder's file
        return held

    monkeypatch.setattr(cam, "_hold", hold_then_lose)
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert f"{folder / 'IMG_0001.dng'} was taken as this light's image" in said, said
    assert "RAW file not found" not in said and f"{incoming / 'IMG_0001.dng'}" not in said
    if folder_file_too:
        assert f"IMG_0001.dng is gone from {folder} too" in said, said
    else:
        assert f"IMG_0001.dng is left in {folder}" in said, said
        assert (folder / "IMG_0001.dng").exists()
    assert "no image was recorded for this light" in said
    assert "did not change within" not in said and clock.now() < 5.0


def test_a_refused_exposure_names_the_folders_file_not_its_renamed_copy(tmp_path: Path) -> None:
    """An earlier copy of the same name in ``.incoming`` gives this one ``IMG_0001_2.dng``: the
    refusal names ``IMG_0001.dng``, the file the user's program saved."""
    folder = tmp_path / "tether"
    folder.mkdir()
    clock = ScriptedClock({0.5: lambda: _dng(folder / "IMG_0001.dng", exposure_s=1 / 30)})
    cam, incoming = _bound_camera(tmp_path, clock)
    incoming.mkdir(parents=True)
    _dng(incoming / "IMG_0001.dng")  # an earlier shot's copy, kept
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert "IMG_0001.dng was exposed" in said and "IMG_0001_2" not in said, said
    assert (folder / "IMG_0001.dng").exists()
