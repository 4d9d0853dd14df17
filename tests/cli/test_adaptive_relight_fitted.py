"""The fitted relight design (``optimal --objective relight`` on the object model fitted so far,
``planner.adaptive_relight_design``) offered to ``--objective relight`` through the front door:
`rti-rig run RIG --adaptive --lights N --objective relight` scores it beside the floors' designs
at every decision (format rti-rig-adaptive/9), records a decision that takes it as
``"design": "fitted"``, and an interrupted session that took it resumes to the same session."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import decisions, interrupted, journal
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
DOME = REPO / "rig_configs" / "simulated_dome.toml"
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
runner = CliRunner()
RELIGHT = ("--objective", "relight", "--no-verdict")
#: on this replayed acquisition the fitted relight design is taken at 14 lights, from the
#: second decision on, by 1.77 dB over the best floor's design (checked below). Format 9's start
#: and relight score (clipped renderings, shared held-out lights) changed which N takes it: at
#: 11 lights (the N of format 8, by 0.62 dB) none does now, at 12–17 all do. At 7 lights it had
#: once been taken over the 20° design it equalled only through float32 rounding noise in the
#: fits; with the fits summed in float64 the two tie exactly and the floor's design is kept.
N = 14


def test_a_relight_session_on_the_shipped_dome_scores_the_fitted_design(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(DOME), "--out", str(out), "--adaptive", "--lights", "6", *RELIGHT]
    )
    assert r.exit_code == 0, r.output
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["adaptive"]["format"] == "rti-rig-adaptive/9"
    adaptive = [d for d in decisions(out) if d["kind"] == "adaptive"]
    assert len(adaptive) == 2
    for d in adaptive:
        scores = d["design_psnr_db"]
        # the designs above 0° and 10° are one layout on this dome (its lowest LEDs at 10°)
        assert set(scores) == {"10", "20", "30", "fitted"}
        assert 5.0 < scores["fitted"] < 100.0


@pytest.fixture(scope="module")
def whole(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("relight_fitted") / "s"
    r = runner.invoke(
        app, ["run", str(ACQ), "--out", str(out), "--adaptive", "--lights", str(N), *RELIGHT]
    )
    assert r.exit_code == 0, r.output
    return out


def test_a_relight_decision_that_takes_the_fitted_design_records_it(whole: Path) -> None:
    adaptive = [d for d in decisions(whole) if d["kind"] == "adaptive"]
    assert len(adaptive) == N - 4
    taken = [d for d in adaptive if d.get("design") == "fitted"]
    assert taken, f"the fitted relight design is taken on this acquisition at {N} lights"
    for d in taken:  # names no floor; taken by the margin over the design kept before it
        assert "design_floor_deg" not in d and d["design_objective"] == "relight"
        assert "least expected relighting error on the fitted model" in d["reason"]
        assert d["design_psnr_db"]["fitted"] >= max(d["design_psnr_db"].values()) - 0.5 - 1e-3
    first = taken[0]
    floors = [v for k, v in first["design_psnr_db"].items() if k != "fitted"]
    assert first["design_psnr_db"]["fitted"] >= max(floors) + 0.5 - 1e-3
    manifest = json.loads((whole / "manifest.json").read_text())
    assert [s["decision"] for s in manifest["steps"]] == [s["decision"] for s in journal(whole)]
    # lights.lp lists what fired: the N lights of the journal
    assert len(journal(whole)) == N


def test_an_interrupted_relight_session_that_took_the_fitted_design_resumes_to_the_same_one(
    whole: Path, tmp_path: Path
) -> None:
    out = tmp_path / "cut"
    interrupted(ACQ, out, 5, "relight", lights=N)  # one fitted decision made
    assert len(journal(out)) == 6
    assert journal(out)[5]["decision"].get("design") == "fitted"
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert decisions(out) == decisions(whole)
    assert (out / "lights.lp").read_text() == (whole / "lights.lp").read_text()
