"""`benchmarks.until_error_sensor`: the arm's gap between the stop's upper estimate and the
measured error, split into the rendering's share and the sensor's."""

from __future__ import annotations

import numpy as np

from benchmarks.until_error_sensor import COUNTS, _noisy, measure, table


def test_the_noise_is_fitted_at_the_cameras_level_and_scale() -> None:
    rng = np.random.default_rng(3)
    clean = rng.uniform(0.05, 1.0, (3, 32, 32, 3)).astype(np.float32)
    level = 0.6 * clean
    camera = (level + rng.standard_normal(level.shape) * np.sqrt(4e-4 * level)).astype(np.float32)
    noisy = _noisy(clean, camera)
    lit = clean > 0.02
    # the same scale and the same variance per unit of signal as the camera's
    assert abs(np.median(noisy[lit] / clean[lit]) - np.median(camera[lit] / clean[lit])) < 0.005
    slope = np.mean((noisy - level) ** 2) / np.mean(level)
    assert 3.6e-4 < slope < 4.4e-4, slope
    assert not np.array_equal(noisy, camera)  # drawn, not copied


def test_the_arm_session_is_run_and_split() -> None:
    rows = measure()
    assert [r["k"] for r in rows] == list(COUNTS)
    for r in rows:
        # noise adds error; camera-level noise on the rendering gives the camera's figure
        assert 0.0 < r["clean"] < r["camera"], r
        assert abs(r["noisy"] - r["camera"]) < 0.1, r
        assert r["upper"] >= r["estimate"] > 0, r
    assert "| 4 |" in table(rows)
