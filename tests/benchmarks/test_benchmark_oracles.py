"""The hindsight oracles of the real-dome benchmark (benchmarks.planner_real_data).

They are the bars the planner's objectives are read against, so they must really optimise the
score they claim: here a synthetic dome where one light of the homogeneous starting layout
carries a highlight that no low-order basis can fit.
"""

from __future__ import annotations

import numpy as np

from benchmarks.planner_real_data import hindsight_relight
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.core.rti_bases import design_matrix
from rti_rig.planner.uniform import select_uniform_leds


def _held_out_psnr(sel: np.ndarray, images: np.ndarray, dirs: np.ndarray) -> float:
    """Mean PSNR of an HSH1 fit on ``sel`` relit to every other light."""
    design = design_matrix("hsh1", dirs)
    obs = images.reshape(len(dirs), -1)
    rest = np.setdiff1d(np.arange(len(dirs)), sel)
    pred = design[rest] @ (np.linalg.pinv(design[sel]) @ obs[sel])
    return float(np.mean(-10 * np.log10(np.mean((pred - obs[rest]) ** 2, axis=1))))


def test_relight_oracle_drops_a_highlight_light_and_improves_the_score() -> None:
    rng = np.random.default_rng(0)
    dirs = fibonacci_cap(40, 10.0, 85.0)
    normals = rng.normal([0, 0, 1], 0.15, size=(400, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    images = np.clip(normals @ dirs.T, 0, None).T.reshape(40, 20, 20) * 0.5
    start = select_uniform_leds(DomeGeometry(dirs, tuple(map(str, range(40)))), 6)
    glossy = int(start[np.argmax(dirs[start, 2])])
    images[glossy] += 0.4  # a highlight over the whole (flat, glossy) object

    chosen = hindsight_relight(6, images, dirs, np.ones((20, 20), bool), "hsh1")

    assert len(set(chosen.tolist())) == 6
    assert glossy not in chosen
    assert _held_out_psnr(chosen, images, dirs) > _held_out_psnr(start, images, dirs) + 3.0
