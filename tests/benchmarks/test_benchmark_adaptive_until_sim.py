"""The simulator's ``--until-error`` stop table: the point and the upper stops replayed from one
session (decisions do not depend on the target), claims above target counted."""

from __future__ import annotations

from benchmarks.adaptive_until_sim import report, stop_at


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
    assert stop_at(s, 1.6, 1.0, 10, upper=2.0) == (10, 0.8)  # 2 × 8/k ≤ 1.6 only at k = 10
    assert stop_at(s, 1.0, 1.0, 10, upper=2.0) == (10, 0.8)  # never reached: the end


def test_report_counts_the_claims_above_target() -> None:
    text = report([_session()], (1.6, 4.0), 1.0, 10, "cmd", 1.0, False, upper=2.0)
    rows = [ln for ln in text.splitlines() if ln.startswith("| s | ") and "° |" in ln[:12]]
    # 1.6°: point claims at 5 (measured 3.2° above); upper at 10 (2 × 0.8 = 1.6: measured 1.6°)
    assert rows[0].startswith("| s | 1.6° | 5 | 1.60° | 3.20° **above** | ×2.00 | 10 | 1.60° |")
    # 4°: both claim at 4 lights (point 2°, upper 4°), measured 4.0°: at, not above, the target
    assert rows[1].startswith("| s | 4° | 4 | 2.00° | 4.00° | ×2.00 | 4 | 4.00° | 4.00° |")
    assert "point estimate 1 of 2, upper estimate 0 of 2" in text


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
