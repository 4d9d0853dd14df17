"""The fitted design (``optimal`` on the surface fitted so far, ``planner.adaptive_optimal``)
offered by default through the front door: `rti-rig run ACQ/dirs.lp --adaptive --lights N`
records the decisions that take it as ``"design": "fitted"`` (format rti-rig-adaptive/7; /5
before the relight objective was offered its own), and an interrupted session that took it
resumes to the very same session."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import decisions, journal
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
    assert manifest["adaptive"]["format"] == "rti-rig-adaptive/7"
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
    from rti_rig.app.config import load_rig_config
    from rti_rig.app.usecases.adaptive import open_adaptive_session
    from rti_rig.runtime.controller import CancelToken, StepCompleted, run_session

    out = tmp_path / "cut"
    rig, schedule, folder, source = open_adaptive_session(load_rig_config(ACQ), out, N, None)
    cancel = CancelToken()

    def on_event(event) -> None:  # type: ignore[no-untyped-def]
        if isinstance(event, StepCompleted) and event.index == 4:  # one fitted decision made
            cancel.cancel()

    with rig:
        run_session(rig, schedule, folder, cancel=cancel, on_event=on_event, source=source)
    assert len(journal(out)) == 5
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert decisions(out) == decisions(whole)
    assert (out / "lights.lp").read_text() == (whole / "lights.lp").read_text()
