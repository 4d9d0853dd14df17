"""The under-exposure claim is made only of a session the camera's range shows to be dark.

Found by review: a small object on black, under 0.1 % of the frame and exposed to 0.8 of full
scale, was called "about 6 stops under" (its frame's 99.9th percentile is the background), and
images that do not change with their light (lights that never fired) were told to lengthen
the exposure as well.
"""

from __future__ import annotations

import numpy as np

from rti_rig.reconstruct.qa import assess
from rti_rig.reconstruct.qa_underexposed import UNDEREXPOSED

SIDE = 512


def _lights(n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    el = np.radians(rng.uniform(15.0, 80.0, n))
    az = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)


def _sphere_on_black(radius: float, peak: float, lights: np.ndarray) -> list[np.ndarray]:
    rng = np.random.default_rng(1)
    yy, xx = np.mgrid[0:SIDE, 0:SIDE].astype(float)
    u, v = (xx - SIDE / 2) / radius, -(yy - SIDE / 2) / radius
    inside = u**2 + v**2 < 1.0
    normals = np.stack([u, v, np.sqrt(np.clip(1.0 - u**2 - v**2, 0.0, 1.0))], axis=-1)
    frames = []
    for light in lights:
        shade = np.clip(normals @ light, 0.0, None) * inside * peak + 0.005
        noisy = shade + rng.normal(0.0, 0.001, shade.shape)
        frames.append(np.clip(noisy * 65535.0, 0, 65535).astype(np.uint16))
    return frames


def test_a_small_object_on_black_exposed_well_is_not_called_under_exposed() -> None:
    lights = _lights(24)
    frames = _sphere_on_black(8.0, 0.8, lights)  # 0.07 % of the frame

    report = assess(frames, lights, [f"img{i:02d}" for i in range(24)])

    assert max(c.peak_level for c in report.images) < 1 / 32  # the background's level
    assert UNDEREXPOSED not in report.verdict, report.verdict


def test_the_same_object_far_too_dark_is() -> None:
    lights = _lights(24)
    frames = _sphere_on_black(40.0, 0.02, lights)  # 1.9 % of the frame, at 2 % of full scale

    report = assess(frames, lights, [f"img{i:02d}" for i in range(24)])

    assert f"24 images: {UNDEREXPOSED}" in report.verdict, report.verdict


def test_images_that_do_not_change_are_not_told_to_lengthen_the_exposure() -> None:
    """One dim picture (a smooth texture at 1.2 % of full scale) under every light."""
    rng = np.random.default_rng(2)
    yy, xx = np.mgrid[0:256, 0:256]
    picture = (0.5 + 0.5 * np.sin(xx / 9.0) * np.cos(yy / 13.0)) * 0.012
    frames = [
        np.clip((picture + rng.normal(0, 0.00002, picture.shape)) * 65535, 0, 65535).astype(
            np.uint16
        )
        for _ in range(12)
    ]

    report = assess(frames, _lights(12), [f"img{i:02d}" for i in range(12)])

    assert "do not change with their light" in report.verdict, report.verdict
    assert UNDEREXPOSED not in report.verdict, report.verdict
