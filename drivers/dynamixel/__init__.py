"""Dynamixel Protocol 2.0 servo-arm light carrier.

Modules, from bytes up: :mod:`protocol2` (pure packet codec), :mod:`control_table` (X-series
addresses, units, fault bits), :mod:`settings` (validated arm config), :mod:`kinematics`
(direction <-> joint ticks, reachability), :mod:`faults` (named errors), :mod:`bus` (the one
place that talks to the official ``dynamixel_sdk``) and :mod:`arm` (the ``LightCarrier``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rti_rig.core.lazy_names import lazy_getattr

# The names below are loaded on first use (PEP 562): importing one light module of this
# package (its settings, for a rig config) must not import the driver, its transport and the
# vendor library (``rti-rig plan`` reads a config but drives nothing).
_WHERE = {
    "ArmKinematics": "rti_rig.drivers.dynamixel.kinematics",
    "ArmSettings": "rti_rig.drivers.dynamixel.settings",
    "CommunicationError": "rti_rig.drivers.dynamixel.faults",
    "ConfigMismatchError": "rti_rig.drivers.dynamixel.faults",
    "DynamixelArm": "rti_rig.drivers.dynamixel.arm",
    "DynamixelError": "rti_rig.drivers.dynamixel.faults",
    "HardwareFaultError": "rti_rig.drivers.dynamixel.faults",
    "JointSettings": "rti_rig.drivers.dynamixel.settings",
    "MoveTimeoutError": "rti_rig.drivers.dynamixel.faults",
    "SafetyViolation": "rti_rig.drivers.dynamixel.faults",
    "ServoStatusError": "rti_rig.drivers.dynamixel.faults",
    "UnreachableError": "rti_rig.drivers.dynamixel.faults",
}

if TYPE_CHECKING:
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


__getattr__ = lazy_getattr(__name__, _WHERE, globals())


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
