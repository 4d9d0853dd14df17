"""``plan``'s summary says what was done, and its advice offers only what was not chosen.

``--method optimal --lights 3`` keeps the uniform layout, yet the summary said "(optimal,
normals)"; the note on many optimised lights said "--method uniform --min-elevation-deg 10 did
better" even to a user who had typed ``--min-elevation-deg 20``, and as options, not a command.
"""

from __future__ import annotations

import shlex
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app

DOME = CONFIGS / "simulated_dome.toml"


def _plan(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, *args: str) -> str:
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(app, ["plan", "--rig", str(DOME), *args], terminal_width=400)
    assert r.exit_code == 0, r.output
    return " ".join(r.output.split())


def test_three_optimal_lights_say_the_uniform_layout_was_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    said = _plan(tmp_path, monkeypatch, "--method", "optimal", "--lights", "3", "--out", "p.lp")
    assert "(optimal, normals)" not in said
    assert "Planned 3 lights (the uniform ≥0° layout, not optimised: 3 lights leave no" in said


def _advice(said: str) -> list[str]:
    cmd = said.split("did better (", 1)[1].split(")", 1)[0]
    return shlex.split(cmd)


def test_a_typed_floor_is_not_advised_against(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "p-uniform.lp").write_text("taken\n")
    said = _plan(
        tmp_path, monkeypatch,
        "--method", "optimal", "--lights", "20", "--min-elevation-deg", "20", "--out", "p.lp",
    )  # fmt: skip
    assert "--min-elevation-deg 10" not in said
    words = _advice(said)
    assert words[:2] == ["rti-rig", "plan"]
    assert words[words.index("--min-elevation-deg") + 1] == "20"
    assert words[words.index("--out") + 1] == "p-uniform-2.lp"  # free: p-uniform.lp is taken
    # the command pastes: run as printed, it plans
    r = CliRunner().invoke(app, words[1:], terminal_width=400)
    assert r.exit_code == 0, r.output
    assert (tmp_path / "p-uniform-2.lp").is_file()


def test_no_floor_typed_is_advised_the_tested_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    said = _plan(tmp_path, monkeypatch, "--method", "optimal", "--lights", "20", "--out", "p.lp")
    words = _advice(said)
    assert words[words.index("--min-elevation-deg") + 1] == "10"
    assert words[words.index("--method") + 1] == "uniform"
