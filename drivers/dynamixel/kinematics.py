"""Light direction <-> joint angles <-> servo ticks, and the safety gate. Pure functions.

Why a *tick-level* gate: the reachability test on directions is a convenience for planners;
what protects the camera is :meth:`ArmKinematics.ticks_reason`, which checks the integers that
will actually be written to Goal Position (after rounding and multi-turn choice). The driver
calls it on every goal it sends, so a bug upstream cannot put a bad command on the bus.

Why endpoints suffice: each X-series joint follows a monotone (trapezoidal) profile to its goal,
so between two safe poses every intermediate joint value lies between the endpoint values. Joint
limits are intervals and the keep-out cone around +z is ``elevation > 90 - half_angle``; with
elevation confined to -90..90 both are convex in joint space, so a path between two safe poses
stays safe.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.geometry import az_el_from_direction, direction_from_az_el
from rti_rig.core.rig_geometry import LIMIT_SLACK_DEG
from rti_rig.drivers.dynamixel import control_table as ct

if TYPE_CHECKING:  # annotations only: settings validates a park pose with these kinematics
    from rti_rig.drivers.dynamixel.settings import ArmSettings, JointSettings

#: Slack when comparing joint angles to limits, for floating-point round trips.
EPS_DEG = 1e-9


def joint_to_ticks(joint: JointSettings, joint_deg: float) -> float:
    """Unrounded servo ticks of a joint angle."""
    return joint.zero_offset_ticks + joint_deg * joint.ticks_per_joint_deg


def ticks_to_joint(joint: JointSettings, ticks: float) -> float:
    """Joint angle in degrees of a servo reading."""
    return (ticks - joint.zero_offset_ticks) / joint.ticks_per_joint_deg


class ArmKinematics:
    """Kinematics and reachability of one configured arm."""

    def __init__(self, settings: ArmSettings) -> None:
        self.settings = settings

    # -- joint level ------------------------------------------------------------------------
    def pose_reason(self, azimuth_deg: float, elevation_deg: float) -> str | None:
        """Why a joint pose is unsafe, or None."""
        s = self.settings
        az, el = s.azimuth, s.elevation
        # a pose a rounding hair past a limit is on it (LIMIT_SLACK_DEG): its ticks are rounded
        # onto the limit's own tick (ticks_of_pose), and the tick gate below stays exact
        slack = LIMIT_SLACK_DEG
        if not az.min_deg - slack <= azimuth_deg <= az.max_deg + slack:
            return f"azimuth joint {azimuth_deg:.3f} deg outside {az.min_deg}..{az.max_deg}"
        if not el.min_deg - slack <= elevation_deg <= el.max_deg + slack:
            return f"elevation {elevation_deg:.3f} deg outside {el.min_deg}..{el.max_deg}"
        limit = 90.0 - s.keep_out_half_angle_deg
        if elevation_deg > limit + slack:
            return (
                f"elevation {elevation_deg:.3f} deg is inside the "
                f"{s.keep_out_half_angle_deg} deg keep-out cone around the camera "
                f"(max {limit:.3f})"
            )
        return None

    def ticks_reason(
        self, azimuth_ticks: int, elevation_ticks: int, what: str = "goal"
    ) -> str | None:
        """THE safety gate: why these Goal Position values must not be sent, or None.

        ``what`` names the ticks in the reason: ``"goal"``, or ``"position"`` for a pose read
        from the servos (connect's check had called the arm's present pose a "goal", as if
        rti-rig had tried to send it there)."""
        s = self.settings
        for name, joint, t in (
            ("azimuth", s.azimuth, azimuth_ticks),
            ("elevation", s.elevation, elevation_ticks),
        ):
            lo, hi = joint.tick_limits
            if not lo <= t <= hi:
                return f"{name} servo {joint.servo_id} {what} {t} ticks outside limits {lo}..{hi}"
        el_deg = ticks_to_joint(s.elevation, elevation_ticks)
        limit = 90.0 - s.keep_out_half_angle_deg
        if el_deg > limit + EPS_DEG:
            return (
                f"elevation {what} {elevation_ticks} ticks = {el_deg:.3f} deg enters the "
                f"keep-out cone (max {limit:.3f} deg)"
            )
        return None

    def ticks_of_pose(self, azimuth_deg: float, elevation_deg: float) -> tuple[int, int]:
        """Rounded goal ticks of a joint pose. The tick limits are the degree limits rounded
        inwards, so a pose on a degree limit can lie up to one tick outside them; such values
        are clamped onto the limit (which is inside the safe range). Anything further out is
        left alone for the gate to refuse."""
        out = []
        cone = 90.0 - self.settings.keep_out_half_angle_deg
        for joint, deg in (
            (self.settings.azimuth, azimuth_deg),
            (self.settings.elevation, elevation_deg),
        ):
            raw = joint_to_ticks(joint, deg)
            lo, hi = joint.tick_limits
            t = round(raw)
            if lo - 1.0 <= raw and t < lo:
                t = lo
            elif raw <= hi + 1.0 and t > hi:
                t = hi
            # a pose on the keep-out cone's edge rounds to the tick outside the cone, not the one
            # a fraction of a tick inside it (which the gate refuses)
            edge = joint is self.settings.elevation and deg <= cone + LIMIT_SLACK_DEG
            if edge and ticks_to_joint(joint, t) > cone + EPS_DEG:
                t = next(
                    (
                        a
                        for a in (math.floor(raw), math.ceil(raw))
                        if lo <= a <= hi and ticks_to_joint(joint, a) <= cone + EPS_DEG
                    ),
                    t,
                )
            out.append(int(t))
        return out[0], out[1]

    def pose_of_ticks(self, azimuth_ticks: float, elevation_ticks: float) -> tuple[float, float]:
        return (
            ticks_to_joint(self.settings.azimuth, azimuth_ticks),
            ticks_to_joint(self.settings.elevation, elevation_ticks),
        )

    def direction_of_ticks(self, azimuth_ticks: float, elevation_ticks: float) -> NDArray:
        """Unit light direction of a servo reading."""
        az, el = self.pose_of_ticks(azimuth_ticks, elevation_ticks)
        return direction_from_az_el(az, el)

    # -- direction level --------------------------------------------------------------------
    def azimuth_candidates(self, azimuth_deg: float) -> list[float]:
        """Joint azimuths (azimuth + k*360) inside the azimuth joint limits."""
        j = self.settings.azimuth
        k0 = math.floor((j.min_deg - azimuth_deg) / 360.0)
        k1 = math.ceil((j.max_deg - azimuth_deg) / 360.0)
        return [
            azimuth_deg + 360.0 * k
            for k in range(k0, k1 + 1)
            if j.min_deg - LIMIT_SLACK_DEG <= azimuth_deg + 360.0 * k <= j.max_deg + LIMIT_SLACK_DEG
        ]

    def solve(
        self, direction: ArrayLike, current_azimuth_deg: float | None = None
    ) -> tuple[tuple[float, float] | None, str | None]:
        """Joint pose for ``direction`` nearest the current azimuth, or (None, reason).

        Multi-turn: any azimuth + k*360 inside the joint limits will do, and the one closest
        to where the arm is now is taken (shortest move). The pose is checked on the rounded
        ticks with :meth:`ticks_reason`, exactly as the driver will check it.
        """
        try:
            az, el = az_el_from_direction(direction)
        except ValueError as exc:
            return None, str(exc)
        az, el = float(az), float(el)
        ref = self.settings.park_azimuth_deg if current_azimuth_deg is None else current_azimuth_deg
        candidates = self.azimuth_candidates(az)
        if not candidates:
            j = self.settings.azimuth
            # in -180..180, as the limits are mostly written: "azimuth 329.342 deg is outside
            # the joint limits -10.0..170.0" read as an arm asked past a full turn
            shown = (az + 180.0) % 360.0 - 180.0
            return None, (
                f"azimuth {shown:.3f} deg is outside the joint limits {j.min_deg}..{j.max_deg}"
            )
        joint_az = min(candidates, key=lambda a: abs(a - ref))
        reason = self.pose_reason(joint_az, el)
        if reason:
            return None, reason
        reason = self.ticks_reason(*self.ticks_of_pose(joint_az, el))
        if reason:
            return None, reason
        return (joint_az, el), None

    def unreachable_reason(self, direction: ArrayLike) -> str | None:
        return self.solve(direction)[1]


def clamp_ticks(joint: JointSettings, ticks: int) -> int:
    """Ticks clamped into the joint's safe tick range."""
    lo, hi = joint.tick_limits
    return int(min(max(ticks, lo), hi))


def wrap_ticks(ticks: int) -> int:
    """One-turn reading of a multi-turn position (0..4095)."""
    return int(ticks) % ct.TICKS_PER_REV


def as_direction(direction: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(direction, dtype=np.float64).reshape(3)
