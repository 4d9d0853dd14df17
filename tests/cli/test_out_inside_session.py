"""A new session's --out inside an existing session folder is refused before the rig opens.

It used to be written there, nested among the finished session's images: a copy, a fit or a
resume of the outer session then carried or stumbled over the inner one.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.errors import SessionError
from rti_rig.runtime.session import FORMAT, JOURNAL, LP_NAME, MANIFEST, SessionFolder

runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    """The command's output with rich's line wrapping undone."""
    return " ".join(result.output.split())


def tree(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` with its SHA-256 (what a user would compare)."""
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.mark.e2e
@pytest.mark.slow
def test_run_refuses_an_out_inside_a_finished_session(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    done = tmp_path / "S"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(done), "--lights", "6"])
    assert r.exit_code == 0, r.output
    before = tree(done)
    for out in (done / "sub", done / "linear" / "deeper" / "still"):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6"])
        assert r.exit_code == 2, r.output
        text = said(r)
        assert f"--out {out} is inside {done}, a finished session" in text, text
        assert "give an --out outside it" in text and "Traceback" not in text
        assert not out.exists()
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(done / "preview")])
    assert r.exit_code == 2 and "a finished session" in said(r), r.output
    assert tree(done) == before  # nothing written into the finished session
    # a sibling, reached through the session's own path, is not inside it
    beside = done / ".." / "T"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(beside), "--lights", "6"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "T" / MANIFEST).is_file()


def _interrupted(root: Path) -> None:
    """The record of a session that was stopped: its manifest says it is still running."""
    root.mkdir()
    manifest = {"format": FORMAT, "runner": {"state": "running", "finish_reason": None}}
    (root / MANIFEST).write_text(json.dumps(manifest), encoding="utf-8")
    (root / JOURNAL).write_text("", encoding="utf-8")


def test_an_interrupted_session_says_how_to_continue_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _interrupted(tmp_path / "S")
    monkeypatch.chdir(tmp_path)  # the session is named as the user gave it, relative
    with pytest.raises(SessionError) as refused:
        SessionFolder.check_new(Path("S/a/b"))
    assert str(refused.value).startswith(
        "--out S/a/b is inside S, an interrupted session (continue it with rti-rig run --resume S)"
    )


@pytest.mark.parametrize("record", [MANIFEST, JOURNAL])
def test_a_record_that_cannot_be_read_still_marks_a_session(tmp_path: Path, record: str) -> None:
    """A damaged manifest, or a journal whose manifest is gone: still a session's folder (not
    one to resume as it is, so no resume is offered)."""
    (tmp_path / "S").mkdir()
    (tmp_path / "S" / record).write_text(json.dumps([1]), encoding="utf-8")
    with pytest.raises(SessionError) as refused:
        SessionFolder.check_new(tmp_path / "S" / "new")
    said = str(refused.value)
    assert f"is inside {tmp_path / 'S'}, a session folder" in said and "--resume" not in said


@pytest.mark.skipif(not hasattr(os, "symlink"), reason="no symbolic links")
def test_a_link_into_a_session_is_inside_it(tmp_path: Path) -> None:
    _interrupted(tmp_path / "S")
    (tmp_path / "S" / "deep").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "S" / "deep")
    with pytest.raises(SessionError, match="is inside"):
        SessionFolder.check_new(tmp_path / "link" / "new")


def test_an_acquisition_or_an_empty_parent_is_no_session(tmp_path: Path) -> None:
    """A folder with only a lights.lp (any tool writes one) is not a session: a new session
    may go inside it, as may one in a plain folder or beside a session."""
    acq = tmp_path / "acq"
    acq.mkdir()
    (acq / LP_NAME).write_text("1\nimage_001.jpg 0.0 0.0 0.999999\n", encoding="utf-8")
    _interrupted(tmp_path / "S")
    for out in (acq / "new", tmp_path / "plain" / "new", tmp_path / "S-2"):
        SessionFolder.check_new(out)
