"""The QA verdict of an interrupted adaptive session that lost an image before its last
names what to do, not the resume that is refused.

``rti-rig fit S`` of such a session (image_003 deleted, 6 of 8 images taken) ended its verdict
"continue it with rti-rig run --resume S", which the resume refuses: each later light was
chosen from image_003, so it cannot be reshot in place.
"""

from __future__ import annotations

from pathlib import Path

from conftest import SMALL_DOME, interrupted, journal, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_the_verdict_of_an_adaptive_session_with_a_gap_names_the_way_on(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    interrupted(cfg, out, 5, lights=8)
    assert len(journal(out)) == 6
    (out / "image_003.jpg").unlink()

    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")], terminal_width=400)
    text = said(r)
    assert "Traceback" not in r.output, r.output
    assert "the session is not finished" in text, text
    assert "an adaptive session cannot reshoot image_003 in place" in text, text
    assert "put the original files back" in text, text
    assert f"continue it with rti-rig run --resume {out})" not in text, text
    # as the resume says: refused, nothing moved
    r = runner.invoke(app, ["run", "--resume", str(out)], terminal_width=400)
    assert r.exit_code == 2 and "image_003" in said(r), r.output


def test_the_verdict_of_an_adaptive_session_that_lost_its_last_image_still_says_resume(
    tmp_path: Path,
) -> None:
    """Its last image is the one a resume sets aside and shoots again (nothing was chosen from
    it yet)."""
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    interrupted(cfg, out, 5, lights=8)
    (out / "image_006.jpg").unlink()
    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")], terminal_width=400)
    text = said(r)
    assert f"continue it with rti-rig run --resume {out}" in text, text
    assert "cannot reshoot" not in text, text
    assert "let its resume set the files aside and shoot the image again" in text, text
