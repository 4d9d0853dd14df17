"""The ceiling benchmark's seeds: the committed draws write docs, fresh draws only print."""

from __future__ import annotations

import argparse

import pytest

import benchmarks.planner_ceiling as ceiling


@pytest.fixture
def fake_parts(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, str]]:
    """Stand-ins for the slow parts (they take their seed) and a recorder of doc writes."""
    written: list[tuple[str, str]] = []
    monkeypatch.setattr(ceiling, "sim_rows", lambda seed: [f"| sim rows of seed {seed} |"])
    monkeypatch.setattr(
        ceiling, "real_rows", lambda seed: ([f"| real rows of seed {seed} |"], ["| relit |"])
    )
    monkeypatch.setattr(ceiling, "write_section", lambda name, md, doc: written.append((name, md)))
    return written


def test_the_committed_seed_writes_both_sections(fake_parts: list[tuple[str, str]]) -> None:
    """Seed 0 is the committed tables' draws: each part writes its own section."""
    text = ceiling.main(("sim", "real"))
    assert [name for name, _ in fake_parts] == ["planner_ceiling_sim", "planner_ceiling_real"]
    assert "seed 0" in text and "rows of seed 0" in text and "--seed" not in text


def test_a_fresh_seed_draws_anew_and_only_prints(fake_parts: list[tuple[str, str]]) -> None:
    """Another seed is a check of the committed tables: it must not overwrite them."""
    text = ceiling.main(("real",), seed=1)
    assert fake_parts == []  # the committed table is left alone
    assert "seed 1" in text and "real rows of seed 1" in text
    assert "planner_ceiling real --seed 1`" in text  # the command that reproduces it
    assert "sim rows" not in text


def test_the_command_line_refuses_an_unknown_part() -> None:
    """A typo ('rel') must fail loudly instead of running nothing."""
    assert ceiling.parts_arg("real") == ("real",)
    assert ceiling.parts_arg("sim,real") == ("sim", "real")
    with pytest.raises(argparse.ArgumentTypeError, match="rel"):
        ceiling.parts_arg("rel")
