"""A batch's judgement of an earlier fit and the session's integrity check share one checksum
cache, keyed by what changes whenever a file's content may have (the batch had kept a cache of
its own by path, size and mtime: an image rewritten in place at its size, its time set back,
kept its old checksum, and files the session check had just read were read again)."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import pytest

from rti_rig.app.usecases import fit_batch
from rti_rig.runtime import session


def test_a_rewrite_of_the_same_size_with_its_time_set_back_is_hashed_again(
    tmp_path: Path,
) -> None:
    image = tmp_path / "001.tif"
    image.write_bytes(b"a" * 64)
    before = image.stat()
    assert fit_batch._file_sha256(image) == hashlib.sha256(b"a" * 64).hexdigest()
    with image.open("r+b") as fh:  # in place: the same inode, size and (set back) mtime
        fh.write(b"b" * 64)
    os.utime(image, ns=(before.st_atime_ns, before.st_mtime_ns))
    assert fit_batch._file_sha256(image) == hashlib.sha256(b"b" * 64).hexdigest()


def test_a_file_the_session_check_hashed_is_not_read_again_by_the_batch(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    image = tmp_path / "001.tif"
    image.write_bytes(b"c" * 64)
    digest = session.file_sha256(image)
    read: list[object] = []
    real = hashlib.file_digest

    def counted(fh, name):  # type: ignore[no-untyped-def]
        read.append(fh.name)
        return real(fh, name)

    monkeypatch.setattr(hashlib, "file_digest", counted)
    assert fit_batch._file_sha256(image) == digest and read == []
    assert fit_batch._file_sha256(None) is None
    assert fit_batch._file_sha256(tmp_path / "gone.tif") is None
