"""A path that is not there, given to ``plan`` as the preview or to ``run`` as ``--plan``, is
named as missing, with the option and what to give.

Before: ``plan sessions/nosuch`` said "preview image not found" (a typo in a session folder's
name read as a session whose image was lost), and ``run RIG --plan nosuch.lp`` said
"nosuch.lp: cannot read: No such file or directory", naming no option.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_plan_of_a_preview_that_is_not_there(tmp_path: Path) -> None:
    gone = tmp_path / "sessions" / "nosuch"
    out = tmp_path / "p.lp"
    r = runner.invoke(app, ["plan", str(gone), "--out", str(out)])
    assert r.exit_code == 2, said(r)
    assert f"{gone}: no such file or folder: give a preview image, or the session" in said(r)
    assert "rti-rig plan --rig RIG --lights N --method optimal" in said(r)
    assert "preview image not found" not in said(r) and not out.exists()


def test_run_of_a_plan_that_is_not_there(tmp_path: Path) -> None:
    out = tmp_path / "s"
    dome = str(CONFIGS / "simulated_dome.toml")
    r = runner.invoke(app, ["run", dome, "--plan", str(tmp_path / "nosuch.lp"), "--out", str(out)])
    assert r.exit_code == 2, said(r)
    assert f"--plan {tmp_path / 'nosuch.lp'}: no such file: give the .lp" in said(r), said(r)
    assert not out.exists()
