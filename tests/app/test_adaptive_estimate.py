"""The adaptive loop on a known scene (rendered, so its true normals are known): with N known
it falls back to the homogeneous layout when nothing justifies leaving it, and its calibrated
estimate is within the factor docs/adaptive.md reports of the error actually measured."""

from __future__ import annotations

import numpy as np

from rti_rig.app.usecases.adaptive import AdaptiveChooser, dome_start
from rti_rig.core.geometry import fibonacci_cap
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.planner import adaptive
from rti_rig.planner.uniform import select_uniform_leds
from rti_rig.reconstruct import fit_photometric_stereo
from rti_rig.simulator.sim_scene import lambert_radiance, relief_scene

NOISE = 0.01


def _scene_images(dirs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    scene = relief_scene(48, 64, seed=1)
    rng = np.random.default_rng(0)
    images = np.stack([lambert_radiance(scene, d).mean(axis=-1) for d in dirs])
    images = images + rng.normal(0.0, NOISE, images.shape)
    return np.clip(images, 0.0, None).astype(np.float32), scene.normals


def _run(
    dirs: np.ndarray, images: np.ndarray, n: int, bias_aware: bool | None = None
) -> tuple[list[int], float]:
    geometry = DomeGeometry(dirs, tuple(f"l{i}" for i in range(len(dirs))))
    chooser = AdaptiveChooser(
        dirs, dome_start(geometry, 4, n), n, design_lights=n, bias_aware=bias_aware
    )
    for i in range(n + 1):
        c, _ = chooser.decide(i)
        if c is None:
            break
        chooser.observe(c, dirs[c], images[c])
    est = chooser.conclude()["estimated_error_deg"]
    return chooser.used, float(est)


def test_a_matte_scene_gets_the_homogeneous_layout_and_an_honest_estimate(
    monkeypatch,  # type: ignore[no-untyped-def]
) -> None:
    # the bound favours low light here by ~5 %: with a 10 % margin that is not evidence enough
    # (the bias-aware score, the default, simulates this Lambertian relief within its margin)
    monkeypatch.setattr(adaptive, "DESIGN_MARGIN", 0.10)
    dirs = fibonacci_cap(90, 3.0)
    images, normals = _scene_images(dirs)
    geometry = DomeGeometry(dirs, tuple(f"l{i}" for i in range(len(dirs))))
    used, est = _run(dirs, images, 12)
    # nothing here justifies leaving the default design: it is the homogeneous layout exactly
    want = select_uniform_leds(geometry, 12, adaptive.DESIGN_DEFAULT_FLOOR)
    assert sorted(used) == sorted(want.tolist())
    ps = fit_photometric_stereo(images[used], dirs[used], robust=True)
    cos = np.clip(np.sum(ps.normals * normals, axis=-1), -1.0, 1.0)
    measured = float(np.degrees(np.arccos(cos))[ps.valid].mean())
    assert measured > 0.2  # the noise is real: there is an error to estimate
    # docs/adaptive.md: the estimate is within about ×1.5 on the simulator; ×2 is the bar here
    assert measured / 2 < est < measured * 2, (est, measured)


def test_without_a_margin_the_bound_alone_decides_and_leaves_the_default(
    monkeypatch,  # type: ignore[no-untyped-def]
) -> None:
    dirs = fibonacci_cap(90, 3.0)
    images, _ = _scene_images(dirs)
    geometry = DomeGeometry(dirs, tuple(f"l{i}" for i in range(len(dirs))))
    monkeypatch.setattr(adaptive, "DESIGN_MARGIN", 0.0)
    used, _ = _run(dirs, images, 9, bias_aware=False)
    homs = {f: sorted(select_uniform_leds(geometry, 9, f).tolist()) for f in (0, 10, 20, 30)}
    # without a margin the bound's preference alone decides: it leaves the default design
    assert sorted(used) != homs[10]
