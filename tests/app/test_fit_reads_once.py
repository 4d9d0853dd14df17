"""A fit checks a session's linear TIFFs from its own read of them, not from a second one.

Why: at 24 MP a session's TIFFs are ~144 MB each; ``fit`` read every one to fit it and once
more whole to checksum it against the journal. The fit goes through every row of each TIFF
in order anyway, so the pixel checksum the journal holds is taken on the way: the check is
the same (the pixels fitted are the pixels captured), the second read is gone. An edited TIFF
is still named and a re-saved one still accepted: tests/runtime/test_session_integrity.py.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

import rti_rig.runtime.session as session_module
from rti_rig.cli import app
from rti_rig.core.image_files import tiff_pixels_sha256, write_linear_tiff
from rti_rig.core.tiff_rows import TiffRows

runner = CliRunner()


@pytest.fixture(scope="module")
def captured(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("reads_once")
    cfg = write_config(base, SMALL_DOME)
    out = base / "session"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8", "--no-verdict"])
    assert r.exit_code == 0, r.output
    return out


def fresh_copy(src: Path, dest: Path) -> Path:
    """A copy (new files: no checksum this process took of the originals applies to them)."""
    shutil.copytree(src, dest)
    return dest


def read_whole(path: Path, monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Record the files the session's integrity check reads whole from now on."""
    read: list[str] = []
    sha, pixels = session_module.file_sha256, session_module.tiff_pixels_sha256

    def counted_sha(p: Path) -> str | None:
        read.append(Path(p).relative_to(path).as_posix())
        return sha(p)

    def counted_pixels(p: Path) -> str | None:
        read.append(Path(p).relative_to(path).as_posix())
        return pixels(p)

    monkeypatch.setattr(session_module, "file_sha256", counted_sha)
    monkeypatch.setattr(session_module, "tiff_pixels_sha256", counted_pixels)
    return read


def test_a_fit_reads_no_linear_tiff_a_second_time_to_check_it(
    captured: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    done = fresh_copy(captured, tmp_path / "s")
    read = read_whole(done, monkeypatch)
    r = runner.invoke(app, ["fit", str(done), "--out", str(tmp_path / "fit"), "--model", "ps"])
    assert r.exit_code == 0, r.output
    assert json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"] == "good"
    assert [n for n in read if n.startswith("linear/")] == [], read
    assert any(n.endswith(".jpg") for n in read), read  # the JPEGs are still checked


def test_rows_read_in_order_give_the_pixel_checksum_and_nothing_else_does(
    tmp_path: Path,
) -> None:
    path = tmp_path / "a.tif"
    img = np.random.default_rng(0).integers(0, 65535, (37, 11, 3), dtype=np.uint16)
    write_linear_tiff(path, img)
    expected = tiff_pixels_sha256(path)

    rows = TiffRows(path)
    for a in range(0, 37, 5):  # bands in order, the last one short
        rows[a : min(a + 5, 37)]
    assert rows.pixel_digest is not None and rows.pixel_digest[1] == expected

    skipped = TiffRows(path)
    skipped[0:10]
    skipped[20:37]  # rows 10..19 never read: no checksum
    assert skipped.pixel_digest is None

    touched = TiffRows(path)
    touched[0:20]
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))  # written meanwhile
    touched[20:37]
    assert touched.pixel_digest is None
