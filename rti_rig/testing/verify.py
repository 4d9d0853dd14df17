"""An independent check that each image of a simulated session was lit as its record says.

The controller's bookkeeping could be wrong in exactly the way that matters (a lost reply, a
retry that lit the previous LED), so the check does not trust it: it re-renders the scene,
noise-free, for the recorded light and for every other light the rig has, and asks which one
explains the captured linear image best (least squares with a free gain).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rti_rig.app.config import load_rig_config, rig_geometry
from rti_rig.core.image_files import read_linear_tiff
from rti_rig.core.rig_geometry import DomeGeometry
from rti_rig.runtime.session import read_manifest
from rti_rig.simulator.sim_scene import renderer_for


def wrong_light_steps(config_path: Path, session_dir: Path) -> list[int]:
    """Indices of steps whose image is better explained by another light than the recorded one."""
    loaded = load_rig_config(config_path)
    cam, scene_cfg = loaded.config.camera, loaded.config.scene
    render = renderer_for(
        scene_cfg.name, cam.height, cam.width, scene_cfg.seed, scene_cfg.light_distance_mm
    )
    steps = read_manifest(session_dir)["steps"]
    candidates = [tuple(s["actual_direction"]) for s in steps]
    geometry = rig_geometry(loaded)
    if isinstance(geometry, DomeGeometry):
        candidates += [tuple(d) for d in geometry.directions]
    renders = np.stack([render(np.array(d), 1.0).ravel() for d in candidates])
    wrong = []
    for i, step in enumerate(steps):
        img = read_linear_tiff(session_dir / step["linear_image"]).astype(np.float64).ravel()
        # Clipped pixels (a glossy highlight past the white level) carry no shape of the
        # radiance; they are left out of the fit rather than allowed to dominate it.
        keep = img < 0.98 * img.max() if np.any(img >= 65535) else np.ones(img.shape, bool)
        r = renders[:, keep]
        gain = r @ img[keep] / np.maximum((r**2).sum(axis=1), 1e-12)
        residual = ((img[keep][None] - gain[:, None] * r) ** 2).sum(axis=1)
        best = candidates[int(np.argmin(residual))]
        if not np.allclose(best, candidates[i], atol=1e-9):
            wrong.append(step["index"])
    return wrong
