"""The slip benchmark's scoring: one run, held to the emulator's record."""

from __future__ import annotations

from pathlib import Path

from benchmarks.flash_sync_slips import run_once


def test_a_caught_double_step_scores_at_the_slip_with_nothing_mislabelled(tmp_path: Path) -> None:
    r = run_once("relief", (20, "double_step"), tmp_path / "s")
    assert r == {"caught": 20, "wrong_in_lp": 0, "disowned": False, "by_proof": False}


def test_a_double_step_only_the_proof_frame_sees_scores_as_caught_by_it(tmp_path: Path) -> None:
    """On the coin the per-image check misses it; the images after it are in lights.lp with
    wrong lights, and the run is disowned by the end-of-run proof."""
    r = run_once("coin", (17, "double_step"), tmp_path / "s")
    assert r["by_proof"] is True and r["disowned"] is True and r["caught"] == 61
    assert r["wrong_in_lp"] == 60 - 17  # images 18..60 were one LED ahead
