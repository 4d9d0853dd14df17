"""Where an arm was left at the end of a session, as established by reading it back.

Why: ``run`` ended every arm session with "lamp off and stop were requested", whether the arm
had parked, had been left where it stopped (``park_after_session = false``, or an emergency
stop), or had failed to park; the manifest did not record it either. ``check`` said
"parked" or "NOT parked"; a session now says as much, and never more than was read back:
"parked" only of a park that returned and a position read back within
:data:`PARK_TOLERANCE_DEG` of the park pose.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np

from rti_rig.core.devices import LightCarrier
from rti_rig.core.geometry import angle_between_deg, az_el_from_direction, direction_from_az_el

#: A read-back position this close to the park pose (degrees, great circle) is "parked": the
#: arm self-test's pose tolerance (:data:`rti_rig.runtime.arm_check.TOLERANCE_DEG`).
PARK_TOLERANCE_DEG = 1.0

Outcome = Literal["parked", "left", "park-unconfirmed"]


@dataclass(frozen=True)
class ArmEnd:
    """The arm's state after a session's teardown (recorded as the manifest's
    ``runner.arm_end``).

    ``outcome``: ``"parked"`` (park commanded, read back at the park pose), ``"left"`` (no park
    by policy: the arm stays where it stopped) or ``"park-unconfirmed"`` (a park wanted but not
    attempted, failed, or not read back at the park pose); ``azimuth_deg``/``elevation_deg``:
    the position read back (None when it could not be read); ``why``: what kept the park from
    being confirmed, or why the position is unknown; ``torque``: what the carrier's close did
    to the joints' torque when it released them (``torque_policy = "release_on_close"``, see
    :meth:`rti_rig.drivers.dynamixel.arm.DynamixelArm.torque_release_note`), None when it
    released nothing. Why: the close comes after the teardown's read-back, and ``run`` had
    said "held where it stopped, torque on" of an arm its close then let go limp.
    ``torque_at_close``: what the close established of the torque, for a script
    (:meth:`rti_rig.core.devices.TorqueAtClose.to_dict`: the policy, whether a torque-off was
    sent, Torque Enable read back per servo), None when the carrier's close did not say (it
    failed before its torque policy, or the carrier does not read its servos back)."""

    outcome: Outcome
    azimuth_deg: float | None = None
    elevation_deg: float | None = None
    why: str | None = None
    torque: str | None = None
    torque_at_close: dict[str, Any] | None = None

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ArmEnd:
        """The record read back from a manifest (unknown keys ignored)."""
        outcome = str(data.get("outcome"))
        if outcome not in ("parked", "left", "park-unconfirmed"):
            raise ValueError(f"not an arm end outcome: {outcome!r}")
        az, el = data.get("azimuth_deg"), data.get("elevation_deg")
        why, torque = data.get("why"), data.get("torque")
        at_close = data.get("torque_at_close")
        return cls(
            outcome,  # type: ignore[arg-type]
            None if az is None else float(az),
            None if el is None else float(el),
            None if why is None else str(why),
            None if torque is None else str(torque),
            dict(at_close) if isinstance(at_close, dict) else None,
        )

    def _at(self) -> str:
        if self.azimuth_deg is None or self.elevation_deg is None:
            return ""
        return f"az {self.azimuth_deg:.1f}°, el {self.elevation_deg:.1f}°"

    def sentence(self) -> str:
        """What the user is told of the arm (no capital, no full stop), with what the close
        did to its torque, if it released it."""
        said = self._where()
        return f"{said}; {self.torque}" if self.torque else said

    def _where(self) -> str:
        at = self._at()
        if self.outcome == "parked":
            return (
                f"the arm parked (read back at {at}, within {PARK_TOLERANCE_DEG:g}° of its "
                "park pose)"
            )
        if self.outcome == "left":
            why = f"; {self.why}" if self.why else ""
            if at:
                return f"the arm was not parked and is left at {at} (read back{why})"
            # no position: the why says whether it was not read or may still be moving ("left
            # where it stopped" had been said beside "the stop failed, so it may still be moving")
            return f"the arm was not parked ({self.why})"
        where = f"; read back at {at}" if at else ""
        return f"the arm's park is NOT confirmed: {self.why}{where}"


def read_pose(carrier: LightCarrier) -> tuple[float, float] | str:
    """(azimuth, elevation) in degrees read back from ``carrier``, or why it could not be.

    Asked by name (:class:`LightCarrier` declares it; both arms have it), where a ``getattr``
    had answered "this arm cannot report its position" for a misspelt name."""
    try:
        direction = np.asarray(carrier.reached_direction(), dtype=np.float64)
    except Exception as exc:  # a silent or faulted servo: said, not raised in a teardown
        return f"its position could not be read back ({exc})"
    az, el = az_el_from_direction(direction)
    az_f = float(az)
    return (az_f - 360.0 if az_f >= 180.0 else az_f), float(el)


def park_end(carrier: LightCarrier, failure: str | None) -> ArmEnd:
    """The end of a park that was commanded (``failure``: its error, None if it returned)."""
    pose = read_pose(carrier)
    at = (None, None) if isinstance(pose, str) else pose
    if failure is not None:
        return ArmEnd("park-unconfirmed", *at, f"the park failed ({failure})")
    if isinstance(pose, str):
        return ArmEnd("park-unconfirmed", None, None, pose)
    park = carrier.park_pose_deg
    park_az, park_el = park
    off = float(angle_between_deg(direction_from_az_el(*pose), direction_from_az_el(*park)))
    if off > PARK_TOLERANCE_DEG:
        return ArmEnd(
            "park-unconfirmed",
            *pose,
            f"read back {off:.1f}° from the park pose (az {park_az:g}°, el {park_el:g}°)",
        )
    return ArmEnd("parked", *pose)


def left_end(carrier: LightCarrier, why: str) -> ArmEnd:
    """The end of an arm not parked by policy (``why``: which policy)."""
    pose = read_pose(carrier)
    if isinstance(pose, str):
        return ArmEnd("left", None, None, f"{why}; {pose}")
    return ArmEnd("left", *pose, why)
