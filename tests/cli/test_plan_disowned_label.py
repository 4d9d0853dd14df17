"""``rti-rig plan IMAGE`` of an image in a session whose labels are disowned (its
LABELS_NOT_VERIFIED.txt) refuses the light that session records, as fit and export-lp refuse
the session, and plans from the light given by hand.

Before: plan took the recorded light of such a session (a camera-triggered dome's, stepped
twice) without a word, the one reader that did."""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_plan_refuses_a_disowned_sessions_label_and_takes_one_given(tmp_path: Path) -> None:
    dome = str(CONFIGS / "simulated_dome.toml")
    session = tmp_path / "s"
    r = runner.invoke(app, ["run", dome, "--out", str(session), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    (session / "LABELS_NOT_VERIFIED.txt").write_text("the dome stepped twice at image 4\n")
    image = session / "linear" / "image_001.tif"
    line = ["plan", str(image), "--rig", dome, "--lights", "6"]
    r = runner.invoke(app, [*line, "--out", str(tmp_path / "p.lp")])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "may be labelled with the wrong lights" in said and "--preview-light AZ,EL" in said
    assert not (tmp_path / "p.lp").exists()
    r = runner.invoke(app, [*line, "--preview-light", "0,60", "--out", str(tmp_path / "q.lp")])
    assert r.exit_code == 0, r.output
