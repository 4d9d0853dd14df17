"""In-process fault injection around simulated devices, for tests and the fault campaign.

Wrappers raise the errors real devices raise (a camera that times out, a light source whose reply
never comes) at a chosen call. Byte-level faults (garbled serial replies, servo hardware errors)
belong to the device emulators; these model what reaches the controller.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError, DeviceError
from rti_rig.simulator.sim_lights import move_named


@dataclass
class FaultPlan:
    """Raise ``kind`` at the ``at``-th call (0-based) of the wrapped operation."""

    kind: str
    at: int
    fired: list[str] = field(default_factory=list)
    calls: int = 0

    def due(self) -> bool:
        """Count one call of the wrapped operation; True (and recorded) when the fault is due."""
        n, self.calls = self.calls, self.calls + 1
        if n == self.at:
            self.fired.append(self.kind)
            return True
        return False


class FaultyCamera:
    """A camera that fails once, as a camera that stops answering would."""

    def __init__(self, inner, plan: FaultPlan) -> None:  # type: ignore[no-untyped-def]
        self.inner, self.plan = inner, plan
        self.name = inner.name

    def connect(self) -> None:
        self.inner.connect()

    def close(self) -> None:
        self.inner.close()

    def capture(self, exposure_s: float) -> Frame:
        if self.plan.due():
            raise CaptureError(self.name, f"injected fault: {self.plan.kind}", "capture")
        return self.inner.capture(exposure_s)


class FaultyLightSource:
    """A dome whose `light` command fails once (no acknowledgement, port gone)."""

    def __init__(self, inner, plan: FaultPlan) -> None:  # type: ignore[no-untyped-def]
        self.inner, self.plan = inner, plan
        self.name = inner.name

    def connect(self) -> None:
        self.inner.connect()

    def close(self) -> None:
        self.inner.close()

    def light_count(self) -> int:
        return self.inner.light_count()

    def light(self, index: int, intensity: float = 1.0) -> None:
        if self.plan.due():
            raise DeviceError(self.name, f"injected fault: {self.plan.kind}", f"light {index}")
        self.inner.light(index, intensity)

    def all_off(self) -> None:
        self.inner.all_off()

    def __getattr__(self, name: str):  # type: ignore[no-untyped-def]
        return getattr(self.inner, name)


class FaultyCarrier:
    """An arm whose `move_to` fails once (a servo error surfacing mid-move), named by the pose
    it was moving to as the real arm's errors are."""

    def __init__(self, inner, plan: FaultPlan) -> None:  # type: ignore[no-untyped-def]
        self.inner, self.plan = inner, plan
        self.name = inner.name

    def __getattr__(self, name: str):  # type: ignore[no-untyped-def]
        return getattr(self.inner, name)

    def move_to(self, direction: np.ndarray) -> np.ndarray:
        if self.plan.due():
            raise DeviceError(self.name, f"injected fault: {self.plan.kind}", move_named(direction))
        return self.inner.move_to(direction)


class ServoFaultCarrier:
    """An emulated Dynamixel arm whose servos fail at the ``at``-th move (byte level).

    The fault is injected into the servo emulator just before the move is commanded, so the
    real driver meets it in the bytes it reads back: a Hardware Error Status bit (overload,
    overheating), corrupted CRCs, or a servo that stops answering.
    """

    def __init__(self, inner, emulator, plan: FaultPlan, servo_id: int) -> None:  # type: ignore[no-untyped-def]
        self.inner, self.emulator, self.plan = inner, emulator, plan
        self.servo_id = servo_id
        self.name = inner.name

    def __getattr__(self, name: str):  # type: ignore[no-untyped-def]
        return getattr(self.inner, name)

    def move_to(self, direction: np.ndarray) -> np.ndarray:
        from rti_rig.simulator import dynamixel_table as tbl

        if self.plan.due():
            kind = self.plan.kind
            if kind == "servo-overload":
                self.emulator.inject_hardware_error(self.servo_id, tbl.OVERLOAD_ERROR)
            elif kind == "servo-overheating":
                self.emulator.inject_hardware_error(self.servo_id, tbl.OVERHEATING_ERROR)
            elif kind == "servo-corrupt-crc":
                self.emulator.corrupt_next_replies = 3
            elif kind == "servo-silence":
                self.emulator.silent_ids.add(self.servo_id)
            else:
                raise ValueError(f"unknown servo fault {kind!r}")
        return self.inner.move_to(direction)
