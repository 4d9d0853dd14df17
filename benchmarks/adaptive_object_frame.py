"""Homogeneous layouts about the object's own mean normal: a design family probed for issue #28
and not shipped (``python -m benchmarks.adaptive_reach --object-frame``).

Why: every homogeneous design the adaptive chooser offers is homogeneous about the *camera*
axis, its floor an elevation above the camera-frame horizon. A tilted object (the simulator's
tilted plane faces azimuth 50°, elevation 40°) sees such a layout lopsidedly: lights on the
far side graze it or fall behind its plane and are lost to every pixel. The layouts here are
the same equal-area layouts and the same completion of the lights shot so far
(:func:`rti_rig.planner.adaptive.homogeneous_completion`), built in the frame whose pole is the
object's mean normal: the floor is measured from the object's plane, and a candidate behind
that plane (or below the floor) is never taken while enough candidates lie above it.

For a level object the frame is the camera's and the layout is exactly the camera-frame one;
below :data:`MIN_TILT_DEG` the estimated normal is treated as level (a level object's
estimate is off by noise, and a layout rotated by that noise would be a different design that
means nothing). What it measured, and why it does not ship: docs/adaptive.md, "Homogeneous
about the object's mean normal".
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

#: Below this tilt (°) of the estimated mean normal from the camera axis the object is taken
#: as level: its object-frame layout is the camera-frame one.
MIN_TILT_DEG = 10.0
#: Whether a light already shot behind the object's plane is left out of the layout the others
#: are completed to (it lights nothing: the layout is of the lights that count).
DROP_BEHIND = True


def mean_normal(normals: NDArray[np.float64]) -> NDArray[np.float64]:
    """A robust unit mean normal of per-pixel normals (P, 3): the component-wise median,
    normalised (the camera axis when none is finite). Why the median: at the first decision
    many pixels are solved from three ill-conditioned lights and scatter by 7°-17°, while
    their centre is within about 1° of a plane's normal (docs/adaptive.md)."""
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    n = n[np.isfinite(n).all(axis=1)]
    if not len(n):
        return np.array([0.0, 0.0, 1.0])
    m = np.median(n, axis=0)
    norm = float(np.linalg.norm(m))
    if norm < 1e-9 or m[2] <= 0.0:
        return np.array([0.0, 0.0, 1.0])
    return m / norm


def tilt_deg(normal: NDArray[np.float64]) -> float:
    """The angle (°) between ``normal`` and the camera axis."""
    return float(np.degrees(np.arccos(np.clip(normal[2], -1.0, 1.0))))


def to_object_frame(normal: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation (3, 3) taking ``normal`` to +z by the shortest arc (about the axis
    z × normal), so that azimuths keep their sense: directions in the object frame are
    ``d @ R.T``. The identity for the camera axis."""
    n = np.asarray(normal, dtype=np.float64) / np.linalg.norm(normal)
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(n, z)
    s, c = float(np.linalg.norm(axis)), float(n @ z)
    if s < 1e-12:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    k = axis / s
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + s * kx + (1.0 - c) * (kx @ kx)


def object_frame_completion(
    candidates: NDArray[np.float64],
    available: NDArray[np.bool_],
    used: NDArray[np.float64],
    n_total: int,
    floor_deg: float,
    normal: NDArray[np.float64],
) -> NDArray[np.intp] | None:
    """Candidate indices completing the lights ``used`` to a homogeneous layout of ``n_total``
    above ``floor_deg`` *measured from the plane whose normal is* ``normal``: the camera-frame
    completion (:func:`~rti_rig.planner.adaptive.homogeneous_completion`, the same ideal
    layout and nearest-candidate matching) applied to every direction rotated into the object's
    frame. Only candidates above the floor in that frame are taken (None: too few are left);
    the ideal layout spans the object-frame elevations the rig's candidates reach there."""
    from rti_rig.planner.adaptive import homogeneous_completion

    rot = np.eye(3) if tilt_deg(normal) < MIN_TILT_DEG else to_object_frame(normal)
    used_obj = np.asarray(used, dtype=np.float64).reshape(-1, 3) @ rot.T
    if DROP_BEHIND:
        # a light shot behind the plane lights no pixel of it: it holds no place of the layout
        front = used_obj[:, 2] > 0.0
        n_total -= int((~front).sum())
        used_obj = used_obj[front]
    return homogeneous_completion(candidates @ rot.T, available, used_obj, n_total, floor_deg)
