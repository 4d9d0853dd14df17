"""A session shot on a camera-triggered dome is never advised a command refused for it.

Its resume is refused (the dome's own count went on), and so are ``--reshoot-lost`` and an
unfinished session's ``--rebuild-journal``, which go with a resume. The QA verdict and
export-lp had advised exactly those: "reshoot exactly those … rti-rig run --resume S
--reshoot-lost" of an image deleted from a finished session, "rebuild it … rti-rig run
--resume S --rebuild-journal" and "continue it with rti-rig run --resume S" of a stopped one.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, cut_new_session, said
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

runner = CliRunner()
SHIPPED = CONFIGS / "emulated_cceh_rti.toml"


@pytest.fixture(scope="module")
def shot(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(a completed session on the shipped camera-triggered dome, one stopped after 5 images)."""
    base = tmp_path_factory.mktemp("flash")
    done = base / "done"
    r = runner.invoke(app, ["run", str(SHIPPED), "--out", str(done), "--no-verdict"])
    assert r.exit_code == 0, r.output
    stopped = base / "stopped"
    run = cut_new_session(NewSessionRequest(SHIPPED, stopped), after_step=4)
    assert run.finish_reason is FinishReason.CANCELLED
    # the labels checked by hand, as the marker allows: the session is then used
    (stopped / "LABELS_NOT_VERIFIED.txt").unlink()
    return done, stopped


def test_an_image_lost_from_a_finished_session_is_not_sent_to_reshoot_lost(
    shot: tuple[Path, Path], tmp_path: Path
) -> None:
    out = tmp_path / "s"
    shutil.copytree(shot[0], out)
    (out / "image_003.jpg").unlink()
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "image_003.jpg missing since capture" in said(r)
    assert "--reshoot-lost" not in said(r) and "--resume" not in said(r)
    assert "put the originals back from a copy; a camera-triggered dome (cceh-rti)" in said(r)
    again = f"then shoot the session again: rti-rig run {SHIPPED} --out {out}-again"
    assert "long-press its start button to rewind it" in said(r) and again in said(r)
    r = runner.invoke(app, ["run", "--resume", str(out), "--reshoot-lost"])
    assert r.exit_code == 2  # what it had advised


def test_a_stopped_session_without_its_journal_is_not_sent_to_a_resume(
    shot: tuple[Path, Path], tmp_path: Path
) -> None:
    out = tmp_path / "s"
    shutil.copytree(shot[1], out)
    (out / "journal.jsonl").unlink()
    shutil.rmtree(out / "records")  # and its step record files: the manifest alone
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    assert "the session is not finished (5 of 60 images" in said(r)
    assert "--resume" not in said(r), r.output
    assert "restore journal.jsonl from a backup copy of the folder" in said(r)
    assert "cannot continue a session" in said(r)
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 2 and "--resume" not in said(r), r.output
    assert "restore journal.jsonl from a backup copy of the folder" in said(r)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 2 and "cannot be used with a camera-triggered dome" in said(r)


def test_a_finished_session_without_its_journal_is_rebuilt_as_advised(
    shot: tuple[Path, Path], tmp_path: Path
) -> None:
    """No rig is opened for a completed session's rebuild, so the dome's count does not
    matter: the rebuild named is one that works."""
    out = tmp_path / "s"
    shutil.copytree(shot[0], out)
    (out / "journal.jsonl").unlink()
    shutil.rmtree(out / "records")  # and its step record files: the manifest alone
    r = runner.invoke(app, ["export-lp", str(out), "--out", str(tmp_path / "x.lp")])
    assert f"rti-rig run --resume {out} --rebuild-journal" in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    assert r.exit_code == 0 and "whole again" in said(r), r.output
    assert (out / "journal.jsonl").read_bytes() == (shot[0] / "journal.jsonl").read_bytes()
