"""A session whose disk filled so far that its run could not record its end.

The run stops on the full disk (``no-space``), and the manifest's new copy cannot be written
either: it still says ``running`` and ``null``, as during a capture. ``fit``'s verdict then
said "it stopped without recording why (killed, or a power cut?)", a refused resume "its
last run was killed", and the resume that continued it "1 run(s) killed": a user whose disk
had filled went looking for a crash. Now the verdict names the full disk where the session's
disk cannot hold another image like its last one, and the three causes otherwise; nothing
calls the session complete or under way, and the resume keeps every image.
"""

from __future__ import annotations

import errno
import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.testing.disk_faults import failing_writes


def _full_after(monkeypatch: pytest.MonkeyPatch, out: Path, images: int) -> None:
    """The disk of ``out`` reads as full (1 kB free) there once it holds ``images`` images (a
    fit's ``--out`` beside it still has room)."""
    real = shutil.disk_usage

    def usage(path: Any) -> Any:
        u = real(path)
        inside = Path(path).resolve().is_relative_to(out.resolve())
        full = inside and out.is_dir() and len(list(out.glob("image_*.jpg"))) >= images
        return u._replace(free=1_000) if full else u

    monkeypatch.setattr(shutil, "disk_usage", usage)


def test_a_run_the_full_disk_kept_from_recording_its_end_is_said_so(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "6"]
    with monkeypatch.context() as full:
        _full_after(full, out, 3)
        with failing_writes("manifest", after=1, errno_code=errno.ENOSPC) as fault:
            r = CliRunner().invoke(app, [*argv, "--no-verdict"])
        assert fault.failed >= 1  # the end record was refused by the disk, as on a full one
        assert r.exit_code == 2, said(r)
        assert "not enough free disk space" in said(r) and "--resume" in said(r), said(r)
        manifest = json.loads((out / "manifest.json").read_text())
        assert manifest["runner"] == {
            "state": "running",
            "finish_reason": None,
            "steps_planned": 6,
            "steps_done": 0,  # the count when the run began: the end was never recorded
        }

        # the disk still full: the verdict names it, and calls the session not finished
        r = CliRunner().invoke(
            app, ["fit", str(out), "--out", str(tmp_path / "f1"), "--model", "ps"]
        )
        assert r.exit_code == 0, said(r)
        qa = json.loads((tmp_path / "f1" / "qa.json").read_text())
        assert qa["session_complete"] is False
        assert "the session is not finished (3 of 6 images; it stopped without" in qa["verdict"]
        assert "its disk has 0.0 MB free, less than its last image took" in qa["verdict"]
        assert "most likely the disk filled" in qa["verdict"], qa["verdict"]

    # space freed: nothing on disk tells a kill from the full disk, so all three are named
    r = CliRunner().invoke(app, ["fit", str(out), "--out", str(tmp_path / "f2"), "--model", "ps"])
    assert r.exit_code == 0, said(r)
    assert "(killed, a power cut, or a disk too full to record its end)" in said(r), said(r)
    assert "most likely the disk filled" not in said(r)

    r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, said(r)
    assert "3 of 6 images verified on disk" in said(r), said(r)
    assert "1 run(s) killed, powered off or out of disk before recording" in said(r), said(r)
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == "completed" and runner["state"] == "finished"


def test_the_full_disk_is_named_from_a_step_whose_journal_line_it_kept_out(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The disk filled as the journal's lines were to be written: the images are proven by
    their record files alone. The verdict reads the journal once (its records, the record
    files' among them) and sizes the last image from them: it had read the journal again, line
    by line, found no image there, and named three causes where the disk was full."""
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "6"]
    with monkeypatch.context() as full:
        _full_after(full, out, 3)
        with failing_writes("manifest", after=1, errno_code=errno.ENOSPC):
            r = CliRunner().invoke(app, [*argv, "--no-verdict"])
        assert r.exit_code == 2, said(r)
        (out / "journal.jsonl").write_bytes(b"")  # its lines never reached the disk
        assert len(list((out / "records").glob("image_*.json"))) == 3

        r = CliRunner().invoke(
            app, ["fit", str(out), "--out", str(tmp_path / "f"), "--model", "ps"]
        )
        assert r.exit_code == 0, said(r)
        verdict = json.loads((tmp_path / "f" / "qa.json").read_text())["verdict"]
        assert "the session is not finished (3 of 6 images; it stopped without" in verdict
        assert "its disk has 0.0 MB free, less than its last image took" in verdict, verdict
        assert "most likely the disk filled" in verdict, verdict
