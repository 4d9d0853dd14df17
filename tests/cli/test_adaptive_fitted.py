"""The fitted design (``optimal`` on the surface fitted so far, ``planner.adaptive_optimal``)
offered by default through the front door: `rti-rig run ACQ/dirs.lp --adaptive --lights N`
records the decisions that take it as ``"design": "fitted"`` (format rti-rig-adaptive/9; /5
before the relight objective was offered its own), and an interrupted session that took it
resumes to the very same session."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import decisions, interrupted, journal
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
runner = CliRunner()
#: on this replayed acquisition the fitted design is taken at 7 lights (checked below)
N = 7


@pytest.fixture(scope="module")
def whole(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("fitted") / "s"
    r = runner.invoke(app, ["run", str(ACQ), "--out", str(out), "--adaptive", "--lights", str(N)])
    assert r.exit_code == 0, r.output
    return out


def test_by_default_a_session_records_the_fitted_decisions_it_takes(whole: Path) -> None:
    manifest = json.loads((whole / "manifest.json").read_text())
    assert manifest["adaptive"]["format"] == "rti-rig-adaptive/9"
    adaptive = [d for d in decisions(whole) if d["kind"] == "adaptive"]
    assert len(adaptive) == N - 4
    # offered at every design decision, scored beside the floors
    assert all("fitted" in d["design_error_deg"] for d in adaptive)
    taken = [d for d in adaptive if d.get("design") == "fitted"]
    assert taken, "the fitted design is taken on this acquisition at 7 lights"
    for d in taken:  # a fitted decision names no floor, and is the best scored
        assert "design_floor_deg" not in d
        assert "least expected error on the fitted surface" in d["reason"]
    assert [s["decision"] for s in manifest["steps"]] == [s["decision"] for s in journal(whole)]


def test_an_interrupted_session_that_took_the_fitted_design_resumes_to_the_same_one(
    whole: Path, tmp_path: Path
) -> None:
    out = tmp_path / "cut"
    interrupted(ACQ, out, 4, lights=N)  # one fitted decision made
    assert len(journal(out)) == 5
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert decisions(out) == decisions(whole)
    assert (out / "lights.lp").read_text() == (whole / "lights.lp").read_text()
