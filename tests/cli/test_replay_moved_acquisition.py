"""A replay session resumed from its acquisition moved to another folder: its verdict still
finds the recorded files there.

Every later verdict of such a session read the `.lp` the session began with (gone with the
move): a deleted copy under raw/ was called "the camera's original capture is lost … put the
originals back from a copy", though the acquisition, moved, still held the file, and the
recorded names of the images were dropped from the verdict.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from conftest import cut_new_session, journal
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "tests" / "data" / "neuralrti_replay"
runner = CliRunner()


def test_a_verdict_finds_the_recorded_files_in_the_acquisition_moved(tmp_path: Path) -> None:
    from rti_rig.app.usecases.session import NewSessionRequest

    acq = tmp_path / "acq"
    shutil.copytree(SOURCE, acq)
    out = tmp_path / "s"
    cut_new_session(NewSessionRequest(acq / "dirs.lp", out, 8), after_step=3)
    assert len(journal(out)) == 4
    moved = tmp_path / "acq_moved"
    acq.rename(moved)
    r = runner.invoke(app, ["run", str(moved / "dirs.lp"), "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(journal(out)) == 8

    first = json.loads((out / "manifest.json").read_text())["steps"][1]
    copy = next(name for name in first["sha256"] if name.startswith("raw/"))
    (out / copy).unlink()  # the copy of a file recorded before the move
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")], terminal_width=400)
    assert "Traceback" not in r.output, r.output
    verdict = json.loads((tmp_path / "fit" / "qa.json").read_text())["verdict"]
    assert f"{moved}/" in verdict and f"cp -- {moved}/" in verdict, verdict
    assert "original capture is lost" not in verdict, verdict
    assert "the acquisition still holds it as recorded" in verdict, verdict
    assert "clipped in the recording, image09.jpg" in verdict, verdict  # the recorded name
