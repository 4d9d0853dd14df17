"""A watched folder named in a refusal is shown as a shell word (``shown_path``), so a name
with a space or a non-ASCII letter pastes into a shell as the folder on disk.

Why: ten of the folder watch's messages printed ``settings.folder`` raw, so
``/home/me/tether shots`` read as two words and an ``mv`` pasted from it moved the wrong files.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest
from scripted_clock import ScriptedClock

from rti_rig.core.errors import CaptureError
from rti_rig.core.shell_words import shown_path
from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
from rti_rig.drivers.cameras.settings import FolderWatchSettings


def test_the_no_new_file_stop_shows_the_folder_as_a_shell_word(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Nothing arrives under an ASCII locale: the stop names the folder as the ``$'...'`` word
    a shell reads back as its bytes (raw, the streams would print ``?`` for ``Ü``)."""
    for name in ("stdout", "stderr"):
        monkeypatch.setattr(sys, name, io.TextIOWrapper(io.BytesIO(), encoding="ascii"))
    folder = tmp_path / "tether shots Ünï"
    folder.mkdir()
    cam = FolderWatchCamera(
        FolderWatchSettings(folder=folder, timeout_s=2.0, poll_interval_s=0.5),
        clock=ScriptedClock({}),
    )
    cam.output_dir = tmp_path / "s" / "raw" / ".incoming"
    cam.connect()
    with pytest.raises(CaptureError) as info:
        cam.capture(0.5)
    said = str(info.value)
    assert shown_path(folder) != str(folder)  # the name needs quoting: the test can fail
    assert f"in {shown_path(folder)} within" in said, said
    assert f"in {folder} within" not in said, said
