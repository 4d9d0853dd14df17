"""A complete session's resume says it is complete even when its rig config has moved.

Nothing is shot or opened for a session that completed with every image as captured, so its
rig is not needed: the resume had been refused for the config that "is not there any more"
(exit 2), where the same session with its config in place is said complete (exit 0, `fit`
named). A session with an image lost still needs its rig (a reshoot): that refusal stands.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

DOME = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"
runner = CliRunner()


def test_a_complete_session_is_said_complete_without_its_moved_config(tmp_path: Path) -> None:
    config = tmp_path / "dome.toml"
    shutil.copy(DOME, config)
    session = tmp_path / "s"
    r = runner.invoke(app, ["run", str(config), "--out", str(session), "--lights", "6",
                            "--no-verdict"])  # fmt: skip
    assert r.exit_code == 0, r.output
    config.rename(tmp_path / "moved.toml")
    before = sorted(p.name for p in session.rglob("*"))
    r = runner.invoke(app, ["run", "--resume", str(session)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "this session is complete: all 6 steps were captured" in said, said
    assert "rti-rig fit" in said and "not there any more" not in said, said
    assert sorted(p.name for p in session.rglob("*")) == before  # nothing changed
    # an image lost: its reshoot needs the rig, which is asked for
    next(session.glob("image_003.*")).unlink()
    r = runner.invoke(app, ["run", "--resume", str(session)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "is not there any more (moved or renamed?)" in said, said
