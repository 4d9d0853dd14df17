"""The real-dome ``--until-error`` table: what each column says is what the rows hold."""

from __future__ import annotations

from benchmarks.adaptive_until_real import report


def _row(target: float, lights: int, estimate: float | None, measured: float) -> dict:
    return {
        "draw": 0,
        "leds": 72,
        "target": target,
        "lights": lights,
        "estimate": estimate,
        "measured": measured,
        "reached": estimate is not None and estimate <= target,
        "seconds": 1.0,
    }


def test_report_summarises_each_target() -> None:
    rows = [
        _row(2.0, 30, 1.9, 3.8),  # stopped, claiming 1.9°, measured 3.8°
        _row(2.0, 60, 2.5, 1.25),  # the cap, estimate still above the target
        _row(4.0, 11, 3.6, 3.6),
    ]
    text = report(rows, "python -m benchmarks.adaptive_until_real", 1.0)
    lines = {ln.split(" |")[0]: ln for ln in text.splitlines() if ln.startswith("| ")}
    two = lines["| 2°"]
    assert "| 2 | 45 (30–60) |" in two  # draws, median and range of lights
    assert "2.20°" in two and "2.52°" in two  # mean estimate, mean measured
    assert "×1.00 (0.50–2.00)" in two  # geometric mean and range of measured / estimate
    assert "1 of 2" in two  # measured above the target
    assert "estimate reached 1, cap 1" in two
    four = lines["| 4°"]
    assert "×1.00 (1.00–1.00)" in four and "0 of 1" in four and "estimate reached 1, cap 0" in four
