"""Dynamixel Protocol 2.0 servo-arm light carrier.

Modules, from bytes up: :mod:`protocol2` (pure packet codec), :mod:`control_table` (X-series
addresses, units, fault bits), :mod:`settings` (validated arm config), :mod:`kinematics`
(direction <-> joint ticks, reachability), :mod:`faults` (named errors), :mod:`bus` (the one
place that talks to the official ``dynamixel_sdk``) and :mod:`arm` (the ``LightCarrier``).
"""

from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.faults import (
    CommunicationError,
    ConfigMismatchError,
    DynamixelError,
    HardwareFaultError,
    MoveTimeoutError,
    SafetyViolation,
    ServoStatusError,
    UnreachableError,
)
from rti_rig.drivers.dynamixel.kinematics import ArmKinematics
from rti_rig.drivers.dynamixel.settings import ArmSettings, JointSettings

__all__ = [
    "ArmKinematics",
    "ArmSettings",
    "CommunicationError",
    "ConfigMismatchError",
    "DynamixelArm",
    "DynamixelError",
    "HardwareFaultError",
    "JointSettings",
    "MoveTimeoutError",
    "SafetyViolation",
    "ServoStatusError",
    "UnreachableError",
]
