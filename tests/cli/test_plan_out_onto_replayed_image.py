"""`rti-rig plan --rig ACQ/dirs.lp --out ...` never writes the plan over a recorded image of the
acquisition it replays, even with --force: those images are what the command reads (and what
was captured). The rig's .lp and the preview were refused already; a recorded image beside them
was replaced by the plan's text ("6\\nimage_001.jpg ..." in place of the JPEG)."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"
runner = CliRunner()


def test_a_plan_is_not_written_over_an_image_of_the_replayed_acquisition(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    victim = acq / "image05.jpg"
    before = hashlib.sha256(victim.read_bytes()).hexdigest()
    args = ["plan", str(acq / "image01.jpg"), "--rig", str(acq / "dirs.lp"), "--lights", "6"]
    r = runner.invoke(app, [*args, "--out", str(victim), "--force"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    refusal = f"--out {victim} is the recorded image image05.jpg of the rig's .lp"
    assert f"{refusal} this command reads; it is never replaced, even with --force" in said
    assert "Traceback" not in said
    assert hashlib.sha256(victim.read_bytes()).hexdigest() == before
    # an .lp of the user's own beside the images is still theirs to replace
    mine = acq / "plan.lp"
    mine.write_text("old\n")
    r = runner.invoke(app, [*args, "--out", str(mine), "--force"])
    assert r.exit_code == 0, r.output
    assert mine.read_text().splitlines()[0] == "6"
