"""Light schedules: frozen, serialisable data that can be checked without hardware.

A schedule is what the planner produces and the controller consumes. It says, in execution order,
which light to use (a dome LED index, or a direction for an arm) and at what exposure; it never
says how to get there. Schedules are inspected before anything moves (bluesky-style plans as data).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rti_rig.core.geometry import az_el_from_direction, normalize
from rti_rig.core.lp_format import LpEntry


@dataclass(frozen=True)
class LightStep:
    """One exposure of a session.

    ``direction`` is the planned unit light direction; ``led`` is the dome LED index (0-based) when
    the rig is a dome; ``label`` keeps a name the plan came with (e.g. from a dome's `.lp`);
    ``exposure_s`` overrides the rig's default exposure when set.
    """

    direction: tuple[float, float, float]
    led: int | None = None
    label: str = ""
    exposure_s: float | None = None
    intensity: float = 1.0

    def __post_init__(self) -> None:
        d = np.asarray(self.direction, dtype=np.float64)
        if abs(float(np.linalg.norm(d)) - 1.0) > 1e-12 or not np.all(np.isfinite(d)):
            d = normalize(d)  # idempotent for unit input, so a saved schedule reloads bit-exact
        object.__setattr__(self, "direction", (float(d[0]), float(d[1]), float(d[2])))
        if self.led is not None and self.led < 0:
            raise ValueError(f"LED index must be >= 0, got {self.led}")
        if self.exposure_s is not None and not self.exposure_s > 0:
            raise ValueError(f"exposure must be positive, got {self.exposure_s}")
        if not 0.0 < self.intensity <= 1.0:
            raise ValueError(f"intensity must be in (0, 1], got {self.intensity}")

    @property
    def azimuth_deg(self) -> float:
        return float(az_el_from_direction(self.direction)[0])

    @property
    def elevation_deg(self) -> float:
        return float(az_el_from_direction(self.direction)[1])

    def to_dict(self) -> dict[str, Any]:
        return {
            "direction": list(self.direction),
            "led": self.led,
            "label": self.label,
            "exposure_s": self.exposure_s,
            "intensity": self.intensity,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> LightStep:
        return cls(
            direction=tuple(data["direction"]),
            led=data.get("led"),
            label=data.get("label", ""),
            exposure_s=data.get("exposure_s"),
            intensity=data.get("intensity", 1.0),
        )


@dataclass(frozen=True)
class LightSchedule:
    """An ordered, immutable list of light steps and where it came from."""

    steps: tuple[LightStep, ...]
    method: str = "manual"
    provenance: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "steps", tuple(self.steps))

    def __len__(self) -> int:
        return len(self.steps)

    @property
    def directions(self) -> NDArray[np.float64]:
        return np.array([s.direction for s in self.steps], dtype=np.float64).reshape(-1, 3)

    @classmethod
    def from_directions(
        cls,
        directions: ArrayLike,
        leds: Sequence[int | None] | None = None,
        labels: Sequence[str] | None = None,
        method: str = "manual",
        provenance: dict[str, Any] | None = None,
    ) -> LightSchedule:
        dirs = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
        n = len(dirs)
        leds = list(leds) if leds is not None else [None] * n
        labels = list(labels) if labels is not None else [""] * n
        if len(leds) != n or len(labels) != n:
            raise ValueError("directions, leds and labels must have the same length")
        steps = tuple(
            LightStep(direction=tuple(d), led=led, label=lab)
            for d, led, lab in zip(dirs, leds, labels, strict=True)
        )
        return cls(steps=steps, method=method, provenance=dict(provenance or {}))

    def to_lp_entries(self, names: Sequence[str]) -> list[LpEntry]:
        if len(names) != len(self.steps):
            raise ValueError("one name per step is needed")
        return [LpEntry(n, s.direction) for n, s in zip(names, self.steps, strict=True)]

    def to_dict(self) -> dict[str, Any]:
        return {
            "method": self.method,
            "provenance": self.provenance,
            "steps": [s.to_dict() for s in self.steps],
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> LightSchedule:
        return cls(
            steps=tuple(LightStep.from_dict(s) for s in data["steps"]),
            method=data.get("method", "manual"),
            provenance=dict(data.get("provenance", {})),
        )
