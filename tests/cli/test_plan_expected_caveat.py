"""`rti-rig plan` says what its expected errors are, through the front door.

Found by an audit: planned from a preview of the replayed 18-light dome, whose shading the
relief fit explains poorly (R² 0.08), the plan printed "optimal 1.180" expected degrees with no
caveat; the session it planned measured 4.7° mean.
"""

from __future__ import annotations

import re
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def test_a_plan_from_a_poorly_explained_preview_says_its_figures_are_a_lower_bound(
    tmp_path: Path,
) -> None:
    r = runner.invoke(app, ["preview", str(ACQ), "--out", str(tmp_path / "pv")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(
        app,
        [
            "plan",
            str(tmp_path / "pv"),
            "--rig",
            str(ACQ),
            "--lights",
            "9",
            "--out",
            str(tmp_path / "p.lp"),
        ],
    )
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "expected RMS normal error (degrees)" in text
    assert "as a lower bound of what a session measures" in text
    assert re.search(r"the preview's shading fits the relief poorly \(R²=0\.[0-2]\d\)", text)
