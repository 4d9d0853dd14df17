"""The leave-one-scene-out choice of the stop's upper factor (``benchmarks.adaptive_until_bound``):
each scene's factor from the other scenes only, stops replayed from the traces."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from benchmarks.adaptive_until_bound import evaluate, load, main, windowed


def _traces(tmp_path: Path) -> Path:
    """Three scenes whose measured error is 1×, 2× and 3× the estimate at every light count."""
    sessions = []
    for scene, ratio in (("a", 1.0), ("b", 2.0), ("c", 3.0)):
        raw = {str(k): 8.0 / k for k in range(4, 11)}
        meas = {k: ratio * v for k, v in raw.items()}
        sessions.append({"scene": scene, "draw": 0, "used": [], "raw": raw, "measured": meas})
    path = tmp_path / "traces.json"
    path.write_text(json.dumps({"source": "sim", "sessions": sessions}))
    return path


def test_each_scene_factor_comes_from_the_other_scenes(tmp_path: Path) -> None:
    sessions = load(_traces(tmp_path), scale=1.0)
    r = evaluate(sessions, 1.0, 0, (1.0,))  # the maximum ratio of the others
    assert r["factors"] == pytest.approx({"a": 3.0, "b": 3.0, "c": 2.0})
    assert r["all"] == pytest.approx(3.0)
    # upper = f × 8/k; target 1°: reached at k = 8f, beyond the 10 lights traced: all caps
    r = evaluate(sessions, 1.0, 0, (1.0,))
    assert r["claims"] == 0 and r["caps"] == 3
    r = evaluate(sessions, 1.0, 0, (3.5,))
    rows = {row[0]: row for row in r["rows"]}
    assert rows["a"][3] == 7 and rows["a"][4]  # 3 × 8/7 = 3.43 ≤ 3.5: claimed at 7 lights
    assert rows["c"][3] == 5 and rows["c"][4]  # 2 × 8/5 = 3.2 ≤ 3.5 at 5 lights
    assert rows["c"][7] == pytest.approx(3 * 8 / 5)  # measured 4.8° > 3.5°: a broken claim
    assert r["claims"] == 3 and r["above"] == 1  # c's: its ratio is beyond the others'


def test_the_point_rule_and_the_window(tmp_path: Path) -> None:
    sessions = load(_traces(tmp_path), scale=1.0)
    point = evaluate(sessions, None, 0, (3.5,))
    assert point["factors"] == {"a": 1.0, "b": 1.0, "c": 1.0}
    assert point["claims"] == 3 and point["above"] == 2  # b's and c's claims are broken
    # the window: the largest of the last W estimates (falling: the one W lights back)
    w = windowed(sessions[0], 2)
    assert w[4] == pytest.approx(2.0) and w[7] == pytest.approx(8 / 5)
    text = main([str(_traces(tmp_path)), "--targets", "1,3.5", "--scale", "1", "--detail", "q1"])
    assert "| q1 | 3.00, 3.00, 2.00 | 3.00 |" in text
    assert "**above**" in text


def test_the_images_rows_weigh_the_misfit_bound_and_the_unsolved_share(tmp_path: Path) -> None:
    """``+images``: the shipped stop (``upper_error_deg``) replayed on the traced image terms:
    a misfit bound above the factor × the point estimate, or unsolved pixels, hold a claim
    back; the factor-alone rule ignores them."""
    path = _traces(tmp_path)
    data = json.loads(path.read_text())
    for s in data["sessions"]:
        s["misfit"] = {str(k): (4.0 if k < 9 else 0.0) for k in range(4, 11)}
        s["unsolved"] = {str(k): 0.0 for k in range(4, 11)}
    data["sessions"][0]["unsolved"]["9"] = 0.04  # 3.6° at 9 lights on scene a
    path.write_text(json.dumps(data))
    sessions = load(path, scale=1.0)
    alone = {r[0]: r for r in evaluate(sessions, None, 0, (3.5,), fixed=1.0)["rows"]}
    shipped = {r[0]: r for r in evaluate(sessions, None, 0, (3.5,), 1.0, images=True)["rows"]}
    assert alone["a"][3] == 4  # 8/4 = 2 ≤ 3.5 at once
    assert shipped["b"][3] == 9  # the bound, 4°, holds every count below 9
    assert shipped["b"][5] == pytest.approx(8 / 9)
    assert shipped["a"][3] == 10  # at 9 its unsolved share adds 3.6° to 8/9: past 3.5°
    text = main([str(path), "--targets", "3.5", "--scale", "1"])
    assert "| f1.95+images | 1.95, 1.95, 1.95 |" in text
    assert "hold no image terms" not in text


def test_traces_without_image_terms_say_so(tmp_path: Path) -> None:
    text = main([str(_traces(tmp_path)), "--targets", "3.5", "--scale", "1", "--fixed", "1.95"])
    assert "3 of 3 sessions' traces hold no image terms" in text
    f = next(ln for ln in text.splitlines() if ln.startswith("| f1.95 |"))
    g = next(ln for ln in text.splitlines() if ln.startswith("| f1.95+images |"))
    assert f.split("|")[3:] == g.split("|")[3:]  # nothing weighed: the same stops
