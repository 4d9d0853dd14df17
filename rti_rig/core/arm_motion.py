"""How long a servo arm takes to move the lamp between two directions. Pure functions.

Model: each joint follows the X-series velocity-based trapezoidal profile (accelerate at the
Profile Acceleration, cruise at the Profile Velocity, decelerate), or a triangle when the move
is too short to reach the cruise speed. Both joints start together (one Sync Write), so a move
lasts as long as its slower joint, plus ``settle_time_s`` for the in-position check and the bus.

The settings object is duck-typed (``rti_rig.drivers.dynamixel.settings.ArmSettings`` fits), so the
planner does not import driver code: it needs ``azimuth``/``elevation`` joints with
``min_deg``, ``max_deg``, ``joint_velocity_deg_s`` and ``joint_acceleration_deg_s2``, and
``park_azimuth_deg``, ``park_elevation_deg`` and ``settle_time_s``.

Multi-turn: a direction's azimuth may be reachable as azimuth + k*360 within the joint limits;
like the driver, the model takes the value nearest to where the arm is. For the pairwise
matrix each stop's joint azimuth is fixed once (nearest to the start), which is exact whenever
the azimuth range is under 360 deg and an approximation otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.geometry import az_el_from_direction


@dataclass(frozen=True)
class JointMotion:
    """One joint's travel limits and trapezoid, in joint degrees (what the model reads)."""

    min_deg: float
    max_deg: float
    joint_velocity_deg_s: float
    joint_acceleration_deg_s2: float


@dataclass(frozen=True)
class ArmMotion:
    """An arm's move-time model for a rig that declares no servo settings.

    Why: the simulated arm (``[arm]`` speed, acceleration and elevation limits, no
    ``[arm.dynamixel]``) also cannot wrap its azimuth past ±180°; ordering its stops by angle
    alone sent it the long way round (a 6 s move from -170° to 157.6° in a 12-light plan).
    The composition root fills this from the config, so the planner orders those stops by the
    same model as a Dynamixel arm's."""

    azimuth: JointMotion
    elevation: JointMotion
    park_azimuth_deg: float
    park_elevation_deg: float
    settle_time_s: float = 0.0


def joint_move_time_s(distance_deg: float, velocity_deg_s: float, accel_deg_s2: float) -> float:
    """Duration of a trapezoidal (or triangular) profile over ``distance_deg``."""
    d = abs(distance_deg)
    if d == 0.0:
        return 0.0
    if d < velocity_deg_s * velocity_deg_s / accel_deg_s2:
        return 2.0 * math.sqrt(d / accel_deg_s2)
    return d / velocity_deg_s + velocity_deg_s / accel_deg_s2


def joint_pose(direction: ArrayLike, settings: Any, ref_azimuth_deg: float) -> tuple[float, float]:
    """(joint azimuth, elevation) in degrees for ``direction``, azimuth nearest ``ref``."""
    az, el = az_el_from_direction(direction)
    az, el = float(az), float(el)
    j = settings.azimuth
    k0 = math.floor((j.min_deg - az) / 360.0)
    k1 = math.ceil((j.max_deg - az) / 360.0)
    cands = [
        az + 360.0 * k
        for k in range(k0, k1 + 1)
        if j.min_deg - 1e-9 <= az + 360.0 * k <= j.max_deg + 1e-9
    ]
    if not cands:
        raise ValueError(f"azimuth {az:.3f} deg outside the joint limits {j.min_deg}..{j.max_deg}")
    return min(cands, key=lambda a: abs(a - ref_azimuth_deg)), el


def pose_move_time_s(a: tuple[float, float], b: tuple[float, float], settings: Any) -> float:
    """Move time between two joint poses (azimuth, elevation) in degrees."""
    ja, je = settings.azimuth, settings.elevation
    t_az = joint_move_time_s(b[0] - a[0], ja.joint_velocity_deg_s, ja.joint_acceleration_deg_s2)
    t_el = joint_move_time_s(b[1] - a[1], je.joint_velocity_deg_s, je.joint_acceleration_deg_s2)
    return max(t_az, t_el) + settings.settle_time_s


def move_time_s(from_dir: ArrayLike, to_dir: ArrayLike, settings: Any) -> float:
    """Seconds to move the lamp from ``from_dir`` to ``to_dir`` (model, see module doc)."""
    a = joint_pose(from_dir, settings, settings.park_azimuth_deg)
    b = joint_pose(to_dir, settings, a[0])
    return pose_move_time_s(a, b, settings)


def stop_poses(
    directions: ArrayLike, settings: Any, start: ArrayLike | None = None
) -> list[tuple[float, float]]:
    """Joint poses of [start, *directions]; start defaults to the park pose."""
    if start is None:
        first = (settings.park_azimuth_deg, settings.park_elevation_deg)
    else:
        first = joint_pose(start, settings, settings.park_azimuth_deg)
    poses = [first]
    for d in np.asarray(directions, dtype=np.float64).reshape(-1, 3):
        poses.append(joint_pose(d, settings, first[0]))
    return poses


def move_time_matrix(
    directions: ArrayLike, settings: Any, start: ArrayLike | None = None, cyclic: bool = False
) -> NDArray[np.float64]:
    """(N+1)x(N+1) move times; index 0 is the start pose, i+1 is ``directions[i]``.

    ``cyclic=True`` measures azimuth the short way round (|d| <= 180 deg), an optimistic
    model for multi-turn ranges where the arm can usually unwind either way; check a final
    order with :func:`sequence_time_s`. Vectorised: each joint's trapezoid over all pairs."""
    poses = np.array(stop_poses(directions, settings, start))
    out = np.zeros((len(poses), len(poses)))
    for col, joint in ((0, settings.azimuth), (1, settings.elevation)):
        d = np.abs(poses[:, col][:, None] - poses[:, col][None, :])
        if cyclic and col == 0:
            d = np.minimum(d % 360.0, 360.0 - d % 360.0)
        v, acc = joint.joint_velocity_deg_s, joint.joint_acceleration_deg_s2
        tri = 2.0 * np.sqrt(d / acc)
        trap = d / v + v / acc
        t = np.where(d < v * v / acc, tri, trap)
        out = np.maximum(out, t)
    out += settings.settle_time_s
    np.fill_diagonal(out, 0.0)
    return out


def sequence_time_s(directions: ArrayLike, settings: Any, start: ArrayLike | None = None) -> float:
    """Total move time of visiting ``directions`` in the given order from ``start`` (park if
    None), choosing each multi-turn azimuth nearest the previous one, as the driver does.

    Unlike the pairwise matrix this is exact for multi-turn ranges too; use it to report the
    time of a final order."""
    if start is None:
        pose = (settings.park_azimuth_deg, settings.park_elevation_deg)
    else:
        pose = joint_pose(start, settings, settings.park_azimuth_deg)
    total = 0.0
    for d in np.asarray(directions, dtype=np.float64).reshape(-1, 3):
        nxt = joint_pose(d, settings, pose[0])
        total += pose_move_time_s(pose, nxt, settings)
        pose = nxt
    return total
