"""A replay whose acquisition file cannot be read mid-run names that file, not the session's.

A recorded acquisition on a drive unplugged mid-run (or a file moved or deleted as the run
went) had been said as a failed write of the session's copy: "cannot write S/raw/image_003.jpg:
No such file or directory … check that disk", of a disk that was fine, the file that could
not be read unnamed. It is now "cannot read ACQ/IMG 2.JPG …", with the images kept, and the
resume that takes the run up once the drive is back; that resume completes the session."""

from __future__ import annotations

import math
import shlex
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

import rti_rig.simulator.replay as replay
from rti_rig.cli import app
from tests.conftest import journal, said

runner = CliRunner()


def _acquisition(folder: Path) -> Path:
    """Four small JPEGs, named with a space as Windows exports name them, and their .lp."""
    folder.mkdir()
    rng = np.random.default_rng(3)
    lines = ["4"]
    for i in range(4):
        name = f"IMG {i}.JPG"
        assert cv2.imwrite(str(folder / name), rng.integers(10, 240, (24, 32, 3), np.uint8))
        az, el = math.pi * i / 2, math.radians(40)
        x, y, z = math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)
        lines.append(f"{name} {x:.6f} {y:.6f} {z:.6f}")
    (folder / "dirs.lp").write_text("\n".join(lines) + "\n")
    return folder / "dirs.lp"


def test_a_recorded_file_gone_as_it_is_kept_is_named_and_the_resume_completes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    lp = _acquisition(tmp_path / "acq")
    gone = lp.parent / "IMG 2.JPG"
    aside = tmp_path / "unplugged.JPG"
    read = replay.recorded_frame_pixels

    def read_then_unplugged(path: Path) -> np.ndarray:
        pixels = read(path)
        if path == gone:  # the drive goes between the camera's read and the session's copy
            path.rename(aside)
        return pixels

    monkeypatch.setattr(replay, "recorded_frame_pixels", read_then_unplugged)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--no-verdict"])
    text = said(r)
    assert r.exit_code != 0, text
    assert "cannot write" not in text and "check that disk" not in text, text
    assert f"cannot read {gone}" in text and "2 image(s) are kept" in text, text
    assert f"re-attach the drive that holds {gone}" in text, text
    assert [e["index"] for e in journal(out)] == [0, 1]  # what was captured is all there
    assert not list((out / "raw").glob(".*partial"))
    monkeypatch.undo()
    aside.rename(gone)  # the drive back: the resume said completes the session
    command = text.rsplit("then continue with ", 1)[1].strip().rstrip(".")
    r = runner.invoke(app, [*shlex.split(command)[1:], "--no-verdict"])
    assert r.exit_code == 0, said(r)
    assert [e["index"] for e in journal(out)] == [0, 1, 2, 3]
    assert (out / "raw" / "image_003.jpg").read_bytes() == gone.read_bytes()


def test_a_recorded_file_gone_before_the_camera_reads_it_names_it_and_the_resume(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Unplugged before the replay camera reads the next file: it had been a bare "cannot
    read image …: there is no such file"; it says what brings the file back, with the
    resume command."""
    lp = _acquisition(tmp_path / "acq")
    gone = lp.parent / "IMG 2.JPG"
    read = replay.recorded_frame_pixels

    def unplugged_then_read(path: Path) -> np.ndarray:
        if path == gone:
            path.unlink()
        return read(path)

    monkeypatch.setattr(replay, "recorded_frame_pixels", unplugged_then_read)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--no-verdict"])
    text = said(r)
    assert r.exit_code != 0, text
    assert f"cannot read the recorded file {gone}" in text, text
    assert "re-attach the drive that holds it" in text, text
    assert f"Continue with: rti-rig run --resume {out}" in text, text
    assert [e["index"] for e in journal(out)] == [0, 1]


def test_the_first_recorded_file_gone_as_it_is_kept_leaves_the_folder_to_run_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """At the first image nothing is kept: the folder holds no image, and the same command
    is told (the stop's own line says the folder may be used again), not a resume."""
    lp = _acquisition(tmp_path / "acq")
    gone, aside = lp.parent / "IMG 0.JPG", tmp_path / "unplugged.JPG"
    read = replay.recorded_frame_pixels

    def read_then_unplugged(path: Path) -> np.ndarray:
        pixels = read(path)
        if path == gone:
            path.rename(aside)
        return pixels

    monkeypatch.setattr(replay, "recorded_frame_pixels", read_then_unplugged)
    command = ["run", str(lp), "--out", str(tmp_path / "s"), "--no-verdict"]
    r = runner.invoke(app, command)
    text = said(r)
    assert r.exit_code != 0 and f"cannot read {gone}" in text, text
    assert "then run the same command again" in text and "--resume" not in text, text
    monkeypatch.undo()
    aside.rename(gone)
    r = runner.invoke(app, command)
    assert r.exit_code == 0, said(r)
    assert len(journal(tmp_path / "s")) == 4


def test_a_recorded_file_there_but_refused_by_the_system_is_said_with_its_reason(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A recorded file still in its place whose read the system refuses (a permission, a
    failing drive's I/O error) is said with the system's reason: it had been said to be gone,
    "its drive unplugged, or the file moved or deleted?", of a file the user then finds there."""
    lp = _acquisition(tmp_path / "acq")
    refused = lp.parent / "IMG 1.JPG"
    read = replay.recorded_frame_pixels

    def refused_read(path: Path) -> np.ndarray:
        if path == refused:
            raise PermissionError(13, "Permission denied", str(path))
        return read(path)

    monkeypatch.setattr(replay, "recorded_frame_pixels", refused_read)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--no-verdict"])
    text = said(r)
    assert r.exit_code != 0, text
    assert f"cannot read the recorded file {refused}: Permission denied" in text, text
    assert "moved or deleted" not in text, text
    assert [e["index"] for e in journal(out)] == [0]


@pytest.mark.parametrize("reason", ["EACCES", "EPERM"])
def test_a_write_refused_for_permission_is_told_to_check_permissions_not_the_disk(
    reason: str,
) -> None:
    """A resume of a session folder another user owns had been told "check that disk"."""
    from rti_rig.cli.session import _disk_fix

    said = _disk_fix(reason)
    assert "check that you may write to the session folder" in said and "disk" not in said
    assert _disk_fix("EIO") == "check that disk"
