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
    # without a factor: the stop on the point estimate (format 7)
    lines = {ln.split(" |")[1]: ln for ln in text.splitlines() if ln.startswith("| point")}
    two = lines[" 2°"]
    assert "| 2 | 45 (30–60) |" in two  # draws, median and range of lights
    assert "2.20°" in two and "2.52°" in two  # mean estimate, mean measured
    assert "×1.00 (0.50–2.00)" in two  # geometric mean and range of measured / estimate
    assert "1 of 2" in two  # measured above the target
    assert "estimate reached 1, cap 1" in two
    four = lines[" 4°"]
    assert "×1.00 (1.00–1.00)" in four and "0 of 1" in four and "estimate reached 1, cap 0" in four


def test_report_separates_the_point_and_upper_stops() -> None:
    rows = [
        {**_row(2.0, 30, 1.9, 3.8), "factor": 1.0},
        {**_row(2.0, 60, 1.2, 1.5), "factor": 2.0, "reached": False},
    ]
    text = report(rows, "python -m benchmarks.adaptive_until_real", 1.0)
    point = next(ln for ln in text.splitlines() if ln.startswith("| point estimate | 2°"))
    upper = next(ln for ln in text.splitlines() if ln.startswith("| upper (point × 2) | 2°"))
    assert "1 of 1" in point and "estimate reached 1, cap 0" in point
    assert "0 of 1" in upper and "upper reached 0, cap 1" in upper


def test_the_shipped_rule_weighs_the_images_terms() -> None:
    """``rule_upper`` with images is ``upper_error_deg``; its rows are named as shipped and
    show the upper estimate and the misfit bound each stop compared."""
    from benchmarks.adaptive_until_real import rule_upper

    est = {4: 2.0, 5: 1.0}
    terms = {"misfit": {4: 5.0, 5: 0.5}, "unsolved": {4: 0.0, 5: 0.01}}
    assert rule_upper(est, terms, 4, factor=2.0, images=False) == 4.0
    assert rule_upper(est, terms, 4, factor=2.0, images=True) == 5.0  # the bound above 2 × 2
    assert rule_upper(est, terms, 5, factor=2.0, images=True) == 2.0 + 0.9  # + 1 % × 90°
    assert rule_upper(est, {}, 5, factor=2.0, images=True) == 2.0  # no terms traced: nothing
    rows = [
        {**_row(2.0, 60, 1.0, 1.5), "factor": 2.0, "reached": False, "upper": 2.9},
        {
            **_row(2.0, 60, 1.0, 1.5),
            **{"factor": 2.0, "images": True, "reached": False, "upper": 5.0, "misfit": 5.0},
        },
    ]
    text = report(rows, "python -m benchmarks.adaptive_until_real", 1.0)
    shipped = next(ln for ln in text.splitlines() if ln.startswith("| as shipped"))
    assert shipped.endswith("| upper reached 0, cap 1 | 5.00° | 5.00° |"), shipped
    upper = next(ln for ln in text.splitlines() if ln.startswith("| upper (point × 2) | 2°"))
    assert upper.endswith("| 2.90° |  |"), upper
