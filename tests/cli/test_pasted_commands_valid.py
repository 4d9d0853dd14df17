"""Commands rti-rig prints to paste must themselves be accepted: a refused resume's new-session
command (never --max-saturated without --auto-exposure) and a metered preview's Then: line
(the --max-saturated the preview metered with)."""

from __future__ import annotations

import shlex
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli.app import app

runner = CliRunner()
DOME = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"


def _said(r) -> str:  # type: ignore[no-untyped-def]
    return " ".join((r.output + (r.stderr if r.stderr_bytes else "")).split())


def test_refused_resume_new_session_command_runs(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(DOME), "--out", str(out), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    r = runner.invoke(
        app, ["run", "--resume", str(out), "--lights", "6", "--max-saturated", "0.01"]
    )
    assert r.exit_code == 2, r.output
    new = _said(r).split("start a new session: ", 1)[1]
    words = shlex.split(new)
    assert "--max-saturated" in words and "--auto-exposure" in words, new


def test_metered_preview_then_line_keeps_its_limit(tmp_path: Path) -> None:
    out = tmp_path / "pv"
    args = ["preview", str(DOME), "--auto-exposure", "--max-saturated", "0.005", "--out", str(out)]
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    then = _said(r).split("Then: ", 1)[1].split(" (", 1)[0]
    assert "--auto-exposure --max-saturated 0.005" in then, then
