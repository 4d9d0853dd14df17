"""Simulated light sources: a dome and an arm that keep a shared light state and model time.

They implement the rig protocols, so the controller drives them exactly as it drives hardware.
The simulated camera renders from the shared :class:`LightState`, i.e. from what the light source
actually did, not from what the schedule asked for.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rti_rig.core.arm_motion import joint_move_time_s
from rti_rig.core.clock import Clock
from rti_rig.core.devices import KnownStateLightSource
from rti_rig.core.errors import DeviceError, MoveCancelled
from rti_rig.core.geometry import az_el_from_direction, direction_from_az_el
from rti_rig.core.rig_geometry import ArmGeometry, DomeGeometry


@dataclass
class LightState:
    """What is lit right now: a direction and a relative intensity, or nothing."""

    direction: NDArray[np.float64] | None = None
    intensity: float = 0.0


class SimulatedDome(KnownStateLightSource):
    """An LED dome with calibrated directions; lighting an LED takes ``switch_s``.

    Its link is open while it is connected, and its close switches all off first, as a real
    dome's driver does (:meth:`rti_rig.runtime.dome_policy.DomePolicy.close`): a dry run
    rehearses the real teardown, and what is said of its lights is what it was sent."""

    def __init__(
        self, geometry: DomeGeometry, state: LightState, clock: Clock, switch_s: float = 0.02
    ) -> None:
        self.name = "simulated dome"
        self._geometry = geometry
        self._state = state
        self._clock = clock
        self._switch_s = switch_s
        self._connected = False
        self.lit: int | None = None
        self._switched_off = False
        self.history: list[tuple[float, int | None]] = []

    def connect(self) -> None:
        self._connected = True

    def close(self) -> None:
        """All off while connected, then release (safe twice and after a failed connect)."""
        if self._connected:
            self.all_off()
        self._connected = False

    @property
    def link_open(self) -> bool:
        return self._connected

    def lit_now(self) -> int | None:
        return self.lit

    def switched_off(self) -> bool:
        return self._switched_off

    def light_count(self) -> int:
        return self._geometry.count

    def _require(self, command: str) -> None:
        if not self._connected:
            raise DeviceError(self.name, "not connected; call connect() first", command)

    def light(self, index: int, intensity: float = 1.0) -> None:
        self._require(f"light {index}")
        if not 0 <= index < self._geometry.count:
            raise DeviceError(
                self.name, f"LED {index} does not exist (0..{self._geometry.count - 1})", "light"
            )
        self._clock.sleep(self._switch_s)
        self.lit = index
        self._switched_off = False
        self._state.direction = self._geometry.directions[index].copy()
        self._state.intensity = intensity
        self.history.append((self._clock.now(), index))

    def all_off(self) -> None:
        # Safe state must be reachable even when not connected (teardown after a failed connect).
        self.lit = None
        # received only on an open link: one sent after the close (a teardown after a failed
        # connect) leaves nothing lit, but is not said as switching anything off
        self._switched_off = self._switched_off or self._connected
        self._state.direction = None
        self._state.intensity = 0.0
        self.history.append((self._clock.now(), None))


def arm_az_el(direction: NDArray[np.float64]) -> tuple[float, float]:
    """The arm's azimuth (-180 to 180°) and elevation of a light direction, as its joints and
    the real arm's errors take them."""
    az, el = az_el_from_direction(direction)
    az = float(az)
    return (az - 360.0 if az >= 180.0 else az), float(el)


def move_named(direction: NDArray[np.float64]) -> str:
    """A move as an error names it: by the light's own azimuth (0-360°) and elevation, as a
    user reads them in the check's table and the .lp, with the azimuth joint's angle beside
    it when that is a turn away, as the Dynamixel arm's errors do.

    Why: the code name ``'move_to'`` had been said instead, which names no pose on the rig;
    then the joint's angle alone, so a light at az 200° was said as "az -160.0°", an azimuth
    no light of the plan has (the Dynamixel arm had been corrected for that, not this one)."""
    light_az, el = az_el_from_direction(direction)
    joint_az, _ = arm_az_el(direction)
    light_az = float(light_az)
    joint = "" if abs(joint_az - light_az) < 0.05 else f" (azimuth joint at {joint_az:.1f}°)"
    return f"move to az {light_az:.1f}°, el {float(el):.1f}°{joint}"


class SimulatedArm:
    """A two-axis arm (azimuth, elevation) with quantised joints and trapezoidal moves.

    The azimuth joint turns within [-180°, 180°) without wrapping (a cable forbids endless
    rotation), so a move from 170° to -170° goes the long way round, as on real rigs.
    """

    def __init__(
        self,
        geometry: ArmGeometry,
        state: LightState,
        clock: Clock,
        speed_deg_s: float,
        acceleration_deg_s2: float,
        resolution_deg: float,
        switch_s: float = 0.02,
    ) -> None:
        self.name = "simulated arm"
        self._geometry = geometry
        self._state = state
        self._clock = clock
        self._speed = speed_deg_s
        self._accel = acceleration_deg_s2
        self._res = resolution_deg
        self._switch_s = switch_s
        self._connected = False
        self.joints_deg = (geometry.park_azimuth_deg, geometry.park_elevation_deg)
        self.lamp_on = False
        self.moves: list[tuple[float, float]] = []

    def connect(self) -> None:
        self._connected = True

    def close(self) -> None:
        self._connected = False

    def unreachable_reason(self, direction: NDArray[np.float64]) -> str | None:
        return self._geometry.unreachable_reason(direction)

    def _direction(self) -> NDArray[np.float64]:
        return direction_from_az_el(*self.joints_deg)

    def _move_joints(self, az: float, el: float) -> None:
        az = round(az / self._res) * self._res
        el = round(el / self._res) * self._res
        t = max(
            joint_move_time_s(az - self.joints_deg[0], self._speed, self._accel),
            joint_move_time_s(el - self.joints_deg[1], self._speed, self._accel),
        )
        self._clock.sleep(t)
        self.joints_deg = (az, el)
        self.moves.append(self.joints_deg)
        if self.lamp_on:
            self._state.direction = self._direction()

    def move_to(self, direction: NDArray[np.float64]) -> NDArray[np.float64]:
        if not self._connected:
            raise DeviceError(
                self.name, "not connected; call connect() first", move_named(direction)
            )
        reason = self.unreachable_reason(direction)
        if reason:
            raise DeviceError(self.name, f"refused: {reason}", move_named(direction))
        az, el = arm_az_el(direction)
        self._move_joints(az, el)
        return self._direction()

    def lamp(self, on: bool) -> None:
        self._clock.sleep(self._switch_s)
        self.lamp_on = on
        self._state.direction = self._direction() if on else None
        self._state.intensity = 1.0 if on else 0.0

    def stop(self) -> None:
        """Motion is modelled as complete when ``move_to`` returns, so stopping is immediate."""

    def park(self, cancelled: Callable[[], bool] | None = None) -> None:
        """Lamp off, then the park move. Motion is modelled as one step, so ``cancelled`` (a
        stop asked for during the teardown) is asked once, before it: the arm stays put."""
        self.lamp(False)
        if cancelled is not None and cancelled():
            raise MoveCancelled(self.name, "cancelled before it moved; left where it was", "park")
        self._move_joints(self._geometry.park_azimuth_deg, self._geometry.park_elevation_deg)

    @property
    def park_pose_deg(self) -> tuple[float, float]:
        """(azimuth, elevation) of the park pose: what a read-back position is compared to."""
        return (self._geometry.park_azimuth_deg, self._geometry.park_elevation_deg)

    def reached_direction(self) -> NDArray[np.float64]:
        """The lamp's direction from the joints' present angles (the simulation's read-back)."""
        return self._direction()
