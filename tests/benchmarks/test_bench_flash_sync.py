"""The slip benchmark's scoring: one run, held to the emulator's record."""

from __future__ import annotations

from pathlib import Path

from benchmarks.flash_sync_slips import run_once


def test_a_caught_double_step_scores_at_the_slip_with_nothing_mislabelled(tmp_path: Path) -> None:
    r = run_once("relief", (20, "double_step"), tmp_path / "s")
    assert r == {"caught": 20, "wrong_in_lp": 0, "disowned": False}
