"""A replayed session's verdict checks the acquisition it replayed without hashing every image
of it again: each file's size, mtime and ctime are recorded with its checksum when the session
begins, and only a file whose stamp changed is read.

Why: every `run` and `fit` verdict of a replay hashed the whole acquisition (seconds for 72
16-bit TIFFs) to check it was still the one replayed before naming its files. An image edited
since must still be caught: the verdict then names no recorded file."""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.app import rig_identity
from rti_rig.cli import app
from tests.conftest import said

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
NAMED = re.compile(r"clipped in the recording, (\S+) \(a replayed acquisition")
runner = CliRunner()


@pytest.fixture
def replayed(tmp_path: Path) -> tuple[Path, Path]:
    """A copy of the test acquisition and a session replaying it (no verdict yet)."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    return acq, out


def _verdict_hashing(
    monkeypatch: pytest.MonkeyPatch, session: Path, out: Path
) -> tuple[str, list[str]]:
    """The ``fit`` verdict's words, and the files it read to hash."""
    read: list[str] = []
    real = rig_identity._file_digest

    def counted(path: Path) -> str:
        read.append(Path(path).name)
        return real(path)

    monkeypatch.setattr(rig_identity, "_file_digest", counted)
    r = runner.invoke(app, ["fit", str(session), "--out", str(out)])
    assert r.exit_code == 0, r.output
    return said(r), read


def test_an_untouched_acquisition_is_not_read_again(
    replayed: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    acq, session = replayed
    recorded = json.loads((session / "manifest.json").read_text())["rig"]["identity"]
    images = sorted(p.name for p in acq.glob("*.jpg"))
    assert sorted(recorded["recorded_files"]) == images
    text, read = _verdict_hashing(monkeypatch, session, tmp_path / "fit")
    assert NAMED.search(text), text  # the acquisition checked, its files named
    assert read == [], read


@pytest.mark.parametrize("mtime_kept", [False, True])
def test_an_image_edited_in_place_at_the_same_size_is_caught(
    replayed: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, mtime_kept: bool
) -> None:
    """Edited with its size kept (and, ``mtime_kept``, its mtime set back as ``touch -r``
    does): its ctime tells, it alone is read, and the verdict names no recorded file."""
    acq, session = replayed
    image = sorted(acq.glob("*.jpg"))[3]
    before = image.stat()
    data = bytearray(image.read_bytes())
    data[len(data) // 2] ^= 0xFF
    image.write_bytes(bytes(data))
    if mtime_kept:
        os.utime(image, ns=(before.st_atime_ns, before.st_mtime_ns))
        assert image.stat().st_mtime_ns == before.st_mtime_ns
    assert image.stat().st_size == before.st_size
    text, read = _verdict_hashing(monkeypatch, session, tmp_path / "fit")
    assert read == [image.name], read
    assert "clipped in the recording (a replayed acquisition cannot be reshot)" in text, text
    assert not NAMED.search(text), text


def test_a_session_without_recorded_stamps_hashes_in_full(
    replayed: tuple[Path, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A session begun before the stamps were recorded is checked as before: every image read."""
    acq, session = replayed
    manifest = json.loads((session / "manifest.json").read_text())
    del manifest["rig"]["identity"]["recorded_files"]
    (session / "manifest.json").write_text(json.dumps(manifest))
    text, read = _verdict_hashing(monkeypatch, session, tmp_path / "fit")
    assert NAMED.search(text), text
    assert sorted(read) == sorted(p.name for p in acq.glob("*.jpg"))
