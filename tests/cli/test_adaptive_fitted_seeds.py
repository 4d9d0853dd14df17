"""The fitted design's search seeded from more completions, through the front door:
`rti-rig run rig_configs/simulated_dome.toml --adaptive --lights 9` searches the fitted design
from the floors' completions *and* those above 5°/15°/25°/35°/40°
(``planner.adaptive.FITTED_SEED_FLOORS``, chosen leave one scene out: docs/adaptive.md), and
records format rti-rig-adaptive/6 (a /5 session, whose fitted designs were searched from the
floors alone, is refused on resume: tests/app/test_adaptive_session.py)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
RIG = REPO / "rig_configs" / "simulated_dome.toml"
runner = CliRunner()
N = 9


def test_a_session_searches_the_fitted_design_from_every_floor_s_completion(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import rti_rig.planner.adaptive as adaptive
    import rti_rig.planner.adaptive_optimal as adaptive_optimal

    calls: list[tuple[int, list[set[int]], set[int]]] = []
    real = adaptive_optimal.pinned_optimal_design

    def spy(state, candidates, shot, starts):  # type: ignore[no-untyped-def]
        available = np.ones(len(candidates), dtype=bool)
        available[shot] = False
        seeds = set()
        for f in (*adaptive.DESIGN_FLOORS, 5.0, 15.0, 25.0, 35.0, 40.0):
            c = adaptive.homogeneous_completion(candidates, available, state.lights, N, f)
            if c is not None and c.size:
                seeds.add(frozenset(int(i) for i in c))
        calls.append((len(starts), [set(map(int, s)) for s in starts], seeds))
        return real(state, candidates, shot, starts)

    monkeypatch.setattr(adaptive_optimal, "pinned_optimal_design", spy)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(RIG), "--out", str(out), "--adaptive", "--lights", str(N)])
    assert r.exit_code == 0, r.output
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["adaptive"]["format"] == "rti-rig-adaptive/6"
    assert len(calls) == N - 4  # one fitted design per decision
    for count, starts, seeds in calls:
        # the floors' four completions and the five seed floors' (none of the bands empty on
        # this dome at 9 lights): every one of them a start, and nothing else
        assert count == len(adaptive.DESIGN_FLOORS) + 5
        assert {frozenset(s) for s in starts} == seeds
    steps = [json.loads(x) for x in (out / "journal.jsonl").read_text().splitlines()]
    assert len(steps) == N and len({s["led"] for s in steps}) == N
