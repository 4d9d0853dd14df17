"""`benchmarks.until_error_configs`: a case runs through the CLI and is measured as the
calibration measures (robust photometric stereo to the scene's true normals)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks.until_error_configs import Case, config_text, run_case, table, truth_normals


def test_a_directional_case_drops_the_point_lamps_only() -> None:
    shipped = config_text(Case("simulated_arm.toml", False, None, 1.5))
    directional = config_text(Case("simulated_arm.toml", True, None, 1.5))
    assert "light_distance_mm" in shipped and "light_distance_mm" not in directional
    assert len(shipped.splitlines()) == len(directional.splitlines()) + 1


def test_truth_is_the_configs_scene_at_its_cameras_size() -> None:
    dome = {"scene": {"name": "relief"}, "camera": {"width": 64, "height": 48}}
    arm = {"scene": {"name": "tablet", "seed": 0}, "camera": {"width": 64, "height": 64}}
    for cfg, shape in ((dome, (48, 64, 3)), (arm, (64, 64, 3))):
        n = truth_normals(cfg)
        assert n.shape == shape
        assert np.allclose(np.linalg.norm(n, axis=-1), 1.0)


def test_a_case_is_run_and_measured(tmp_path: Path) -> None:
    case = Case("simulated_arm.toml", True, None, 1.5)
    row = run_case(case, tmp_path)
    assert row["lights"] >= 4 and row["claimed"] == (row["upper"] <= 1.5)
    # robust PS on the arm's own four images of the tablet: well under 5°, not zero
    assert 0.05 < row["mean"] < 5.0 and 0.0 < row["median"] < 5.0, row
    text = table([row])
    assert "| simulated_arm.toml (directional) | every elevation | 1.5° |" in text, text
