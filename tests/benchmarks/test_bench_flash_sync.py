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


def test_a_power_cycle_before_the_first_fit_scores_late_with_the_session_disowned(
    tmp_path: Path,
) -> None:
    """The power cut before image 3 (one of the benchmark's default kinds): the firmware lights
    LED 0 again, before the check has a fit to see it, so images 3.. are labelled two LEDs
    ahead of what lit them until the check sees the shift; the run then says not to use the
    session, and the score says it was late, not caught at its image."""
    r = run_once("relief", (3, "power_cycle"), tmp_path / "s")
    assert r["disowned"] is True and r["by_proof"] is False
    assert isinstance(r["caught"], int) and r["caught"] > 3
    assert r["wrong_in_lp"] == r["caught"] - 3  # images 3 .. caught-1 mislabelled


def test_power_cycle_is_one_of_the_benchmarks_default_faults(monkeypatch, capsys) -> None:  # type: ignore[no-untyped-def]
    """Its campaign covers the power cut with the other faults unless told otherwise."""
    import benchmarks.flash_sync_slips as bench

    ran = _record_faults(monkeypatch, bench)
    bench.main(["--quick", "--scenes", "relief"])
    assert {f[1] for f in ran if f} == {"missed_pulse", "double_step", "power_cycle"}
    assert "power_cycle:" in capsys.readouterr().out


def test_a_power_cut_before_image_1_is_not_counted_as_a_slip(monkeypatch, capsys, tmp_path) -> None:  # type: ignore[no-untyped-def]
    """Before image 1 the firmware's restart from LED 0 changes nothing (the emulator's record
    matches every label), so the full campaign leaves that position out for power_cycle alone:
    it had been scored "never caught", 4 of 60, with nothing mislabelled."""
    import benchmarks.flash_sync_slips as bench

    assert run_once("relief", (1, "power_cycle"), tmp_path / "s")["wrong_in_lp"] == 0
    ran = _record_faults(monkeypatch, bench)
    bench.main(["--scenes", "relief"])
    assert (1, "missed_pulse") in ran and (1, "double_step") in ran
    assert (1, "power_cycle") not in ran and (5, "power_cycle") in ran
    out = capsys.readouterr().out
    assert "power_cycle: caught at the slipped image 0/14 (0%)" in out, out
    assert "missed_pulse: caught at the slipped image 0/15 (0%)" in out, out


def _record_faults(monkeypatch, bench) -> list[object]:  # type: ignore[no-untyped-def]
    """Replace the benchmark's sessions with a record of the faults it would inject."""
    ran: list[object] = []
    monkeypatch.setattr(
        bench,
        "run_once",
        lambda scene, fault, root: (
            ran.append(fault)
            or {"caught": None, "wrong_in_lp": 0, "disowned": False, "by_proof": False}
        ),
    )
    monkeypatch.setattr(bench, "check_time_ms", lambda: (0.0, 0.0))
    return ran
