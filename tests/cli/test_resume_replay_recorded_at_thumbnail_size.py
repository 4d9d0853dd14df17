"""A replay session begun before TIFFs whose thumbnail comes first were read at full size
recorded the thumbnails (16×12 images of a 64×48 acquisition). Its resume now reads the same
files at 64×48 and is refused, rightly: the images would not match. It had been told to "set
it back to continue", which nothing can: a replay rig's camera size is its recorded images'
own. It is told to start a new session, with the command, and that command runs as printed,
with the session's --lights (it had said "with the --lights and plan options this one began
with", and pasted as printed shot every light).

The old session is built with the old reader (IFD0, the thumbnail) standing in for
:func:`rti_rig.core.image_files.tiff_main_image`, as the replay read them then."""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest
import tifffile
from conftest import journal, said
from test_replay_thumbnail_first_tiff import _acquisition
from typer.testing import CliRunner

import rti_rig.core.image_files
from rti_rig.cli import app

runner = CliRunner()


def _old_session(acq: Path, out: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A 6-light replay of ``acq`` read as the old code did (IFD0), cut after three images
    as Ctrl-C does."""
    from rti_rig.app.usecases.session import (
        NewSessionRequest,
        open_new_session,
        run_opened_session,
    )
    from rti_rig.runtime.controller import CancelToken, StepCompleted

    def first_ifd(tif):  # type: ignore[no-untyped-def]
        assert tif.series[0].keyframe is tif.pages[0]  # the series of IFD0: the thumbnail
        return tif.series[0]

    cancel = CancelToken()

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, StepCompleted) and event.index == 2:
            cancel.cancel()

    with monkeypatch.context() as m:
        m.setattr(rti_rig.core.image_files, "tiff_main_image", first_ifd)
        opened = open_new_session(NewSessionRequest(acq / "dirs.lp", out, 6))
        run_opened_session(opened, cancel, on_event)
    assert len(journal(out)) == 3
    identity = json.loads((out / "manifest.json").read_text())["rig"]["identity"]
    assert identity["camera_size"] == "16×12"  # as the old code recorded it
    assert tifffile.imread(next((out / "linear").glob("*.tif"))).shape == (12, 16, 3)


def test_a_replay_recorded_at_thumbnail_size_is_told_to_start_a_new_session(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    acq, out = tmp_path / "acq", tmp_path / "S"
    _acquisition(acq, "ifd")
    _old_session(acq, out, monkeypatch)

    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--resume", str(out)])
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, r.output
    assert "camera size: 16×12 → 64×48" in text, text
    assert "set it back" not in text and "--accept-rig-change" not in text, text
    assert "This session cannot be continued: start a new session" in text, text
    assert len(journal(out)) == 3  # nothing captured, nothing overwritten

    command = re.search(r"\(rti-rig run ([^()]+)\)$", text)
    assert command, text
    args = shlex.split(command.group(1))
    assert args[0] == str(acq / "dirs.lp") and args[1] == "--out", args
    new = Path(args[2])
    assert new.parent == out.parent and not new.exists(), args
    r = runner.invoke(app, ["run", *args])  # the advice runs as printed: its 6 lights too
    assert r.exit_code == 0, r.output
    frames = sorted((new / "linear").glob("*.tif"))
    assert len(frames) == 6
    assert all(tifffile.imread(f).shape == (48, 64, 3) for f in frames)
