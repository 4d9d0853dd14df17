"""Simulated sessions for the fit/QA tests, written in the layout rti_rig.runtime.session writes.

Images are rendered by the project's simulator (scene library, light transport with shadows
and the specular lobe its scenes declare), scaled to 16-bit linear TIFFs with a little noise,
and listed in ``lights.lp``. Faults are injected the way they happen on a rig: a misfired LED
(an almost black image), two lights swapped in the ``.lp``, the object moved a few pixels from
one image on, one over-exposed image.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rti_rig.core.image_files import write_linear_tiff
from rti_rig.core.lp_format import LpEntry, write_lp
from rti_rig.simulator.light_transport import DirectionalLight, render_radiance
from rti_rig.simulator.scenes import make_scene


def _rings(rings: tuple[tuple[float, int, float], ...]) -> np.ndarray:
    """Unit lights in rings of (elevation °, count, azimuth offset °), in that order."""
    out = []
    for el, count, off in rings:
        for k in range(count):
            az = np.radians(off + 360.0 * k / count)
            e = np.radians(el)
            out.append((np.cos(e) * np.cos(az), np.cos(e) * np.sin(az), np.sin(e)))
    return np.array(out)


def dome_lights() -> np.ndarray:
    """A 36-light dome: rings at 15°, 30°, 45°, 60°, 75° elevation."""
    return _rings(((15, 10, 0), (30, 9, 20), (45, 8, 0), (60, 6, 30), (75, 3, 0)))


def grazing_last_lights() -> np.ndarray:
    """36 lights whose last ring is at 10° elevation (taken last, as a planner sorting by
    elevation would): rings at 30°, 45°, 60°, 75°, then 10 lights at 10°."""
    return _rings(((30, 9, 20), (45, 8, 0), (60, 6, 30), (75, 3, 0), (10, 10, 0)))


def make_session(
    root: Path,
    *,
    scene: str = "tablet",
    size: tuple[int, int] = (160, 192),
    misfire: int | None = None,
    swap: tuple[int, int] | None = None,
    move: tuple[int, int, int] | None = None,  # (from image, dx, dy) pixels
    saturate: int | None = None,
    saturate_gain: float = 6.0,
    saturate_channel: int | None = None,  # that channel only (a red object under a warm LED)
    black: int | None = None,  # a misfire that left a black frame (constant 2 of 65535)
    swaps: tuple[tuple[int, int], ...] = (),  # more swapped pairs
    lights: np.ndarray | None = None,
    seed: int = 0,
) -> tuple[Path, np.ndarray, np.ndarray]:
    """Write a session folder; returns (folder, lights as recorded, true normals)."""
    sc = make_scene(scene, size[0], size[1], seed=seed)
    lights = dome_lights() if lights is None else lights
    rng = np.random.default_rng(seed)
    (root / "linear").mkdir(parents=True)
    images = [render_radiance(sc, DirectionalLight(tuple(d))) for d in lights]
    peak = float(np.percentile(np.stack(images), 99.5))
    entries = []
    recorded = lights.copy()
    for i, j in ((swap,) if swap is not None else ()) + tuple(swaps):
        recorded[[i, j]] = recorded[[j, i]]
    for k, img in enumerate(images):
        value = img / peak * 0.8
        if misfire == k:
            value = value * 0.03
        if saturate == k and saturate_channel is None:
            value = value * saturate_gain
        elif saturate == k:
            value[..., saturate_channel] *= saturate_gain
        if move is not None and k >= move[0]:
            value = np.roll(value, shift=(-move[2], move[1]), axis=(0, 1))
        value = value + rng.normal(0.0, 0.002, value.shape)
        if black == k:
            value = np.full_like(value, 2.0 / 65535.0)
        px = np.clip(np.round(value * 65535.0), 0, 65535).astype(np.uint16)
        name = f"image_{k + 1:03d}"
        write_linear_tiff(root / "linear" / f"{name}.tif", px)
        entries.append(LpEntry(f"{name}.jpg", tuple(float(x) for x in recorded[k])))
    write_lp(root / "lights.lp", entries)
    return root, recorded, np.asarray(sc.normals)
