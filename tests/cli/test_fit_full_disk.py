"""A fit whose outputs meet a full disk (or a file-size limit) says so, naming the folder and
the command to run again, and keeps nothing half-written; it had been a Python traceback
(``OSError: [Errno 27] File too large`` from the PTM writer's first truncate, under
``prlimit --fsize``)."""

from __future__ import annotations

import errno
from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

import rti_rig.app.usecases.fit as fit_module
from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
runner = CliRunner()


@pytest.mark.parametrize(
    ("code", "remedy"),
    [
        (errno.ENOSPC, "free space on that disk, or choose an --out on another"),
        (errno.EFBIG, "raise the file-size limit (ulimit -f)"),
    ],
)
def test_an_output_the_disk_cannot_hold_is_named_not_a_traceback(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, code: int, remedy: str
) -> None:
    def full(path, *args, **kwargs):  # type: ignore[no-untyped-def]
        raise OSError(code, "the disk says no")  # as a file object's write names no file

    monkeypatch.setattr(fit_module.exporters, "write_relight_dome", full)
    out = tmp_path / "fit"
    r = runner.invoke(app, ["fit", str(ACQ), "--out", str(out), "--no-ptm", "--no-hsh"])
    text = said(r)
    assert r.exit_code == 2, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), r.exception
    assert f"{ACQ}: the fit could not write its outputs in {out}: the disk says no" in text, text
    assert f"nothing of it was kept ({out} removed) and the session is unchanged" in text
    assert f"{remedy}, then run again: rti-rig fit {ACQ} --out {out}" in text, text
    assert not out.exists()
