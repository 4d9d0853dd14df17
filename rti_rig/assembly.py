"""A rig: lighting + camera + clock + timing, assembled from a config by the composition root."""

from __future__ import annotations

from dataclasses import dataclass

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

    @property
    def name(self) -> str:
        return self.loaded.config.name

    @property
    def camera_config(self) -> CameraConfig:
        return self.loaded.config.camera

    @property
    def timing(self) -> TimingConfig:
        return self.loaded.config.timing
