"""A replay session whose acquisition was moved, or its .lp edited, since it began.

Moved, and the session resumed from the new folder: every later verdict read the `.lp` the
session began with (gone with the move), so a deleted copy under raw/ was called "the camera's
original capture is lost … put the originals back from a copy", though the acquisition, moved,
still held the file, and the recorded names of the images were dropped from the verdict.
Its `.lp`'s lines reordered, every image as recorded: the resume's refusal blamed an image
"edited, replaced or re-exported since", naming none.
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


def test_a_resume_on_the_acquisition_with_its_lp_reordered_says_the_lp_changed(
    tmp_path: Path,
) -> None:
    """The .lp's lines put in another order, every image as recorded: the refusal had blamed
    an image "edited, replaced or re-exported since", naming none."""
    from rti_rig.app.usecases.session import NewSessionRequest

    acq = tmp_path / "acq"
    shutil.copytree(SOURCE, acq)
    out = tmp_path / "s"
    cut_new_session(NewSessionRequest(acq / "dirs.lp", out, 8), after_step=2)
    lp = acq / "dirs.lp"
    count, *lines = lp.read_text().splitlines()
    lp.write_text("\n".join([count, *reversed(lines)]) + "\n")
    before = {p.name: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    r = runner.invoke(app, ["run", "--resume", str(out)], terminal_width=400)
    text = " ".join(r.output.split())
    assert r.exit_code == 2, r.output
    assert "lists the same recorded files as when this session began, each as it was" in text
    assert "the .lp was edited since" in text and "Put the .lp back as it was" in text, text
    assert "re-exported" not in text, text
    assert {p.name: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
