"""The simulator's ``--until-error`` stop table: the point and the upper stops replayed from one
session (decisions do not depend on the target), claims above target counted."""

from __future__ import annotations

import pytest

from benchmarks.adaptive_until_sim import report, shipped_upper, stop_at


def _session() -> dict:
    raw = {k: 8.0 / k for k in range(4, 11)}  # point estimate = raw (scale 1)
    return {
        "scene": "s",
        "draw": 0,
        "used": list(range(10)),
        "raw": raw,
        "measured": {k: 2.0 * v for k, v in raw.items()},  # twice the estimate
        "decision_s": 0.1,
    }


def test_the_upper_stop_waits_for_the_upper_estimate() -> None:
    s = _session()
    assert stop_at(s, 1.6, 1.0, 10) == (5, 1.6)  # 8/5 ≤ 1.6: the point stop at 5 lights
    # the estimate returned is the one the stop compared: the upper one (2 × 0.8 at 10)
    assert stop_at(s, 1.6, 1.0, 10, upper=2.0) == (10, 1.6)  # 2 × 8/k ≤ 1.6 only at k = 10
    assert stop_at(s, 1.0, 1.0, 10, upper=2.0) == (10, 1.6)  # never reached: the end


def test_report_counts_the_claims_above_target() -> None:
    text = report([_session()], (1.6, 4.0), 1.0, 10, "cmd", 1.0, False, upper=2.0)
    rows = [ln for ln in text.splitlines() if ln.startswith("| s | ") and "° |" in ln[:12]]
    # 1.6°: point claims at 5 (measured 3.2° above); upper at 10 (2 × 0.8 = 1.6: measured 1.6°)
    assert rows[0].startswith("| s | 1.6° | 5 | 1.60° | 3.20° **above** | ×2.00 | 10 | 1.60° |")
    # 4°: both claim at 4 lights (point 2°, upper 4°), measured 4.0°: at, not above, the target
    assert rows[1].startswith("| s | 4° | 4 | 2.00° | 4.00° | ×2.00 | 4 | 4.00° | 4.00° |")
    assert "point estimate 1 of 2 (9 lights); ×2 alone 0 of 2 (14 lights)" in text
    # without image terms the shipped stop is the factor's (its columns repeat them)
    assert rows[0].endswith("| 10 | 1.60° | 1.60° | ×1.00 | 10 | 1.60° | 1.60° | ×1.00 |")
    assert "as shipped 0 of 2 (14 lights)" in text


def test_the_shipped_stop_weighs_the_images_misfit_and_unsolved_share() -> None:
    """As ``planner.adaptive_until.upper_error_deg``: the larger of the factor × the point
    estimate and the misfit bound, plus the unsolved share × 90°."""
    s = _session()
    s["misfit"] = {k: (3.5 if k < 8 else 0.1) for k in s["raw"]}  # misfit until 8 lights
    s["unsolved"] = {k: (0.01 if k == 9 else 0.0) for k in s["raw"]}  # 0.9° at 9 lights
    assert shipped_upper(s, 4, 1.0, 2.0) == pytest.approx(4.0)  # 2 × 8/4 above the bound
    assert shipped_upper(s, 6, 1.0, 2.0) == pytest.approx(3.5)  # the bound above 2 × 8/6
    assert shipped_upper(s, 9, 1.0, 2.0) == pytest.approx(16 / 9 + 0.9)
    # 3.2°: the factor alone claims at 5 lights; the bound holds the claim to 8 (2 × 8/8 = 2)
    assert stop_at(s, 3.2, 1.0, 10, upper=2.0) == (5, pytest.approx(3.2))
    assert stop_at(s, 3.2, 1.0, 10, upper=2.0, shipped=True) == (8, pytest.approx(2.0))
    # 1.7°: the factor alone claims at 10 (1.6°); as shipped 9 is held by its unsolved share
    assert stop_at(s, 1.78, 1.0, 10, upper=2.0) == (9, pytest.approx(16 / 9))
    assert stop_at(s, 1.78, 1.0, 10, upper=2.0, shipped=True) == (10, pytest.approx(1.6))
    text = report([s], (3.2,), 1.0, 10, "cmd", 1.0, False, upper=2.0)
    assert "×2 alone 0 of 1 (5 lights); as shipped 0 of 1 (8 lights)" in text


def test_the_traces_keep_the_image_terms_of_every_light_count(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A real (short) session: the stop's two image terms are traced wherever the estimate
    is, as the chooser computed them, so that the bound's replay can weigh them."""
    import json

    from benchmarks.adaptive_until_sim import main

    traces = tmp_path / "t.json"
    main(["--scenes", "tablet", "--cap", "6", "--targets", "4", "--traces", str(traces)])
    (row,) = json.loads(traces.read_text())["sessions"]
    assert set(row["raw"]) == set(row["misfit"]) == set(row["unsolved"]) == {"4", "5", "6"}
    assert all(v is not None and v >= 0 for v in row["misfit"].values()), row["misfit"]
    assert all(0 <= v <= 1 for v in row["unsolved"].values()), row["unsolved"]


def test_the_first_start_option_runs_with_the_start_signature_benchmarks_adaptive_calls(
    monkeypatch,  # type: ignore[no-untyped-def]
) -> None:
    """`--first-start` replaces benchmarks.adaptive's start with its own, which must take the
    objective the session passes (a 3-argument start raised a TypeError)."""
    import benchmarks.adaptive as bench
    from benchmarks.adaptive_until_sim import main

    monkeypatch.setitem(bench.START, "start", bench.START["start"])  # restored afterwards
    text = main(
        ["--first-start", "--scenes", "tablet", "--draws", "1", "--cap", "6", "--targets", "4"]
    )
    assert "| tablet | 4° | " in text
