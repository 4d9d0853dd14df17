"""An arm plan beyond the exact order shows the order search's progress.

``plan --rig rig_configs/simulated_arm.toml --lights 1000`` searched for the least-move order
for over a minute with nothing on screen.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.planner.arm_order import EXACT_MAX, heuristic_order


def _plan(tmp_path: Path, rig: str, lights: int) -> str:
    r = CliRunner().invoke(
        app,
        [
            "plan",
            "--rig",
            str(CONFIGS / rig),
            "--lights",
            str(lights),
            "--out",
            str(tmp_path / "p.lp"),
        ],
        terminal_width=400,
    )
    assert r.exit_code == 0, r.output
    return " ".join(r.output.split())


def test_an_arm_order_search_shows_its_steps_to_the_end(tmp_path: Path) -> None:
    said = _plan(tmp_path, "simulated_arm.toml", EXACT_MAX + 8)
    found = re.search(r"ordering the arm's stops for the least move time \S* (\d+)/(\d+)", said)
    assert found is not None, said
    assert found.group(1) == found.group(2) and int(found.group(2)) > 1


def test_a_dome_plan_shows_no_order_bar(tmp_path: Path) -> None:
    assert "ordering the arm's stops" not in _plan(tmp_path, "simulated_dome.toml", 20)


def test_being_told_progress_does_not_change_the_order() -> None:
    rng = np.random.default_rng(3)
    cost = rng.uniform(0.1, 2.0, (21, 21))
    steps: list[tuple[int, int]] = []
    told = heuristic_order(cost, progress=lambda d, t: steps.append((d, t)))
    assert told == heuristic_order(cost)
    assert [d for d, _ in steps] == list(range(1, len(steps) + 1))
    assert steps[-1][0] == steps[-1][1]
