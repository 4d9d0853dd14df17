"""Validated configuration of a two-axis Dynamixel light arm.

Why validate here, not at move time: a wrong sign or offset can drive the lamp into the camera,
so everything that can be checked without hardware (limits inside the servo's range, park pose
reachable and outside the keep-out cone, profile values the register accepts) fails at load
time with the key that is wrong.

Geometry: joint 1 turns the arm about the camera axis (+z) and sets the light's **azimuth**;
joint 2 tilts it and sets the **elevation** (0 deg grazing, 90 deg on the camera axis). For each
joint, ``servo_ticks = zero_offset_ticks + direction * gear_ratio * joint_deg / (360/4096)``:
``zero_offset_ticks`` is the servo reading when the joint angle is 0, ``direction`` is +1 or -1
and ``gear_ratio`` is servo revolutions per joint revolution.
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.kinematics import ArmKinematics

#: Baud rates that dynamixel_sdk's PortHandler accepts (others make openPort return False).
SDK_BAUDRATES = (
    9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, 921600,
    1000000, 1152000, 2000000, 2500000, 3000000, 3500000, 4000000,
)  # fmt: skip


class JointSettings(BaseModel):
    """One joint driven by one servo."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    servo_id: int = Field(ge=0, le=252)
    model_number: int = Field(description="expected Model Number, e.g. 1060 for XL430-W250")
    operating_mode: Literal["position", "extended_position"] = "position"
    zero_offset_ticks: int = Field(description="servo position when the joint angle is 0")
    direction: Literal[1, -1] = 1
    gear_ratio: float = Field(default=1.0, gt=0.0, le=100.0)
    min_deg: float
    max_deg: float
    profile_velocity_rpm: float = Field(default=20.0, gt=0.0, description="servo shaft rpm")
    profile_acceleration_rev_min2: float = Field(default=2000.0, gt=0.0)

    @field_validator("model_number")
    @classmethod
    def _known_model(cls, v: int) -> int:
        if v not in ct.MODEL_NAMES:
            known = ", ".join(f"{n} ({m})" for n, m in ct.MODEL_NAMES.items())
            raise ValueError(f"model number {v} is not a supported X-series servo; known: {known}")
        return v

    @model_validator(mode="after")
    def _check(self) -> JointSettings:
        if not self.min_deg < self.max_deg:
            raise ValueError(f"min_deg ({self.min_deg}) must be below max_deg ({self.max_deg})")
        lo, hi = self.tick_limits
        bound = (
            (0, ct.MAX_TICK)
            if self.mode == ct.OperatingMode.POSITION
            else (-ct.EXTENDED_TICK_LIMIT, ct.EXTENDED_TICK_LIMIT)
        )
        if lo < bound[0] or hi > bound[1]:
            raise ValueError(
                f"joint range {self.min_deg}..{self.max_deg} deg maps to servo ticks {lo}..{hi}, "
                f"outside {bound[0]}..{bound[1]} allowed in {self.operating_mode} mode; fix "
                "zero_offset_ticks, gear_ratio or the limits (or use extended_position mode)"
            )
        for name, units, top in (
            ("profile_velocity_rpm", self.velocity_units, ct.MAX_PROFILE_VELOCITY_UNITS),
            (
                "profile_acceleration_rev_min2",
                self.acceleration_units,
                ct.MAX_PROFILE_ACCELERATION_UNITS,
            ),
        ):
            if not 1 <= units <= top:
                raise ValueError(f"{name} gives register value {units}, outside 1..{top}")
        return self

    @property
    def mode(self) -> ct.OperatingMode:
        if self.operating_mode == "position":
            return ct.OperatingMode.POSITION
        return ct.OperatingMode.EXTENDED_POSITION

    @property
    def ticks_per_joint_deg(self) -> float:
        """Signed servo ticks per joint degree."""
        return self.direction * self.gear_ratio / ct.DEG_PER_TICK

    @property
    def tick_limits(self) -> tuple[int, int]:
        """Servo ticks (low, high) of the joint limits, rounded *inwards* so both are safe."""
        a = self.zero_offset_ticks + self.min_deg * self.ticks_per_joint_deg
        b = self.zero_offset_ticks + self.max_deg * self.ticks_per_joint_deg
        lo, hi = min(a, b), max(a, b)
        return math.ceil(lo - 1e-9), math.floor(hi + 1e-9)

    @property
    def velocity_units(self) -> int:
        """Profile Velocity register value."""
        return round(self.profile_velocity_rpm / ct.RPM_PER_VELOCITY_UNIT)

    @property
    def acceleration_units(self) -> int:
        """Profile Acceleration register value."""
        return round(self.profile_acceleration_rev_min2 / ct.REV_MIN2_PER_ACCEL_UNIT)

    @property
    def joint_velocity_deg_s(self) -> float:
        """Joint speed on the flat part of the profile (from the quantised register value)."""
        return ct.velocity_units_to_deg_s(self.velocity_units) / self.gear_ratio

    @property
    def joint_acceleration_deg_s2(self) -> float:
        return ct.acceleration_units_to_deg_s2(self.acceleration_units) / self.gear_ratio


class ArmSettings(BaseModel):
    """Everything the arm driver needs; see the module docstring for the geometry."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = "arm"
    port: str = Field(description="serial device, e.g. /dev/ttyUSB0 (or an emulator's pty)")
    baudrate: int = 57600
    azimuth: JointSettings
    elevation: JointSettings
    arm_radius_m: float = Field(default=0.5, gt=0.0, description="lamp distance to the object")
    keep_out_half_angle_deg: float = Field(
        default=15.0, ge=0.0, lt=90.0, description="cone around the camera axis (+z)"
    )
    in_position_tolerance_ticks: int = Field(default=4, ge=0, le=100)
    move_timeout_s: float = Field(default=30.0, gt=0.0)
    poll_interval_s: float = Field(default=0.02, gt=0.0, le=1.0)
    settle_time_s: float = Field(
        default=0.05, ge=0.0, description="per-move overhead in the motion-time model"
    )
    park_azimuth_deg: float = 0.0
    park_elevation_deg: float = 10.0
    torque_policy: Literal["hold", "release_on_close"] = "hold"
    lamp: Literal["software", "servo_led"] = "software"
    lamp_servo_id: int | None = None
    sync_position_limits: bool = Field(
        default=True,
        description="write the joint limits into the servos' Min/Max Position Limit (EEPROM) at "
        "connect so that the servo itself refuses anything outside them",
    )

    @field_validator("baudrate")
    @classmethod
    def _baud(cls, v: int) -> int:
        usable = [b for b in ct.BAUD_CODES.values() if b in SDK_BAUDRATES]
        if v not in SDK_BAUDRATES:
            raise ValueError(
                f"baudrate {v} is not accepted by dynamixel_sdk; use one of "
                f"{', '.join(map(str, usable))} (the rate the servos are set to)"
            )
        if v not in ct.BAUD_CODES.values():
            # the SDK opens the port at it, but no X-series servo can be set to it (Baud Rate,
            # address 8, codes 0–7): the arm had only failed at connect, "no servo answered"
            raise ValueError(
                f"baudrate {v}: no Dynamixel X-series servo runs at it (Baud Rate codes 0–7 "
                f"give {', '.join(map(str, ct.BAUD_CODES.values()))}); set the rate the servos "
                f"are set to, one of {', '.join(map(str, usable))} (Dynamixel Wizard 2.0 shows "
                "it)"
            )
        return v

    @model_validator(mode="after")
    def _check(self) -> ArmSettings:
        if self.azimuth.servo_id == self.elevation.servo_id:
            raise ValueError(f"azimuth and elevation share servo_id {self.azimuth.servo_id}")
        if self.elevation.min_deg < -90.0 or self.elevation.max_deg > 90.0:
            raise ValueError(
                "elevation limits must lie within -90..90 deg (over-the-top poses are not "
                "supported: the keep-out proof relies on elevation moving monotonically)"
            )
        if self.keep_out_half_angle_deg + self.elevation.min_deg >= 90.0:
            raise ValueError("keep-out cone covers the whole elevation range: nothing is reachable")
        if self.lamp == "servo_led" and self.lamp_servo_id not in (
            self.azimuth.servo_id,
            self.elevation.servo_id,
        ):
            raise ValueError("lamp = 'servo_led' needs lamp_servo_id set to one of the arm's ids")
        reason = ArmKinematics(self).pose_reason(self.park_azimuth_deg, self.park_elevation_deg)
        if reason:
            raise ValueError(
                f"park pose (azimuth {self.park_azimuth_deg}, elevation "
                f"{self.park_elevation_deg}) is not safe: {reason}"
            )
        self._check_move_timeout()
        return self

    def _check_move_timeout(self) -> None:
        """``move_timeout_s`` at least the longest move the arm can be sent on.

        A move not in position within ``move_timeout_s`` fails the session ("check for an
        obstruction"), so a timeout shorter than the arm's own longest move — a joint across
        its whole range at its profile — fails every session that asks for it, after images
        were taken (a 2 rpm azimuth with the shipped 20 s timeout: a swing from -165 deg to 165
        deg took 27 s, and the session stopped there). The profile is the X-series trapezoid
        (:func:`rti_rig.core.arm_motion.joint_move_time_s`) with the quantised register
        values; the elevation range is the reachable one (below the keep-out cone)."""
        from rti_rig.core.arm_motion import joint_move_time_s

        top = min(self.elevation.max_deg, 90.0 - self.keep_out_half_angle_deg)
        spans = (
            ("azimuth", self.azimuth, self.azimuth.min_deg, self.azimuth.max_deg),
            ("elevation", self.elevation, self.elevation.min_deg, top),
        )
        role, joint, lo, hi = max(
            spans,
            key=lambda j: joint_move_time_s(
                j[3] - j[2], j[1].joint_velocity_deg_s, j[1].joint_acceleration_deg_s2
            ),
        )
        longest = joint_move_time_s(
            hi - lo, joint.joint_velocity_deg_s, joint.joint_acceleration_deg_s2
        )
        if self.move_timeout_s < longest:
            raise ValueError(
                f"move_timeout_s = {self.move_timeout_s:g} s is shorter than this arm's "
                f"longest move: the {role} joint across its range ({lo:g}..{hi:g} deg) at "
                f"profile_velocity_rpm = {joint.profile_velocity_rpm:g} takes {longest:.1f} s, "
                "so a session that asks for it would stop there with a timeout; raise "
                f"move_timeout_s to {math.ceil(1.5 * longest)} or more, or raise that joint's "
                "profile_velocity_rpm"
            )

    @property
    def servo_ids(self) -> tuple[int, int]:
        return (self.azimuth.servo_id, self.elevation.servo_id)

    @property
    def joints(self) -> tuple[JointSettings, JointSettings]:
        return (self.azimuth, self.elevation)
