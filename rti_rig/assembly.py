"""A rig: lighting + camera + clock + timing, assembled from a config by the composition root."""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

from rti_rig.clock import Clock
from rti_rig.config import CameraConfig, LoadedRig, TimingConfig
from rti_rig.lighting import Lighting
from rti_rig.rig import Camera
from rti_rig.rig_geometry import ArmGeometry, DomeGeometry


@dataclass
class Rig:
    """Everything the controller needs to run a schedule."""

    loaded: LoadedRig
    geometry: DomeGeometry | ArmGeometry
    lighting: Lighting
    camera: Camera
    clock: Clock
    #: Things the rig holds open besides its devices (an emulator's pseudo-terminal…).
    resources: contextlib.ExitStack = field(default_factory=contextlib.ExitStack)

    def close(self) -> None:
        """Release what ``build_rig`` opened; the controller has already made devices safe."""
        self.resources.close()

    def __enter__(self) -> Rig:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def name(self) -> str:
        return self.loaded.config.name

    @property
    def camera_config(self) -> CameraConfig:
        return self.loaded.config.camera

    @property
    def timing(self) -> TimingConfig:
        return self.loaded.config.timing
