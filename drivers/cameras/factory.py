"""Build a camera driver from validated settings (for the rig-config composition root).

Why here and not in the config loader: the loader should not need to know each backend's
constructor; it validates ``[camera]`` with ``parse_camera_settings`` and calls
:func:`build_camera`. Nothing is opened: the controller calls ``connect()``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
from rti_rig.drivers.cameras.gphoto2_camera import Gphoto2Camera
from rti_rig.drivers.cameras.opencv_camera import OpenCvCamera
from rti_rig.drivers.cameras.settings import (
    CameraSettings,
    FolderWatchSettings,
    Gphoto2CameraSettings,
    OpenCvCameraSettings,
)

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Camera


def build_camera(
    settings: CameraSettings,
    clock: Clock | None = None,
    output_dir: Path | None = None,
    trigger: Callable[[float], None] | None = None,
    gp_module: Any = None,
) -> Camera:
    """The driver for ``settings``; ``output_dir`` is where a DSLR's downloads go (session
    folder), ``trigger`` fires a folder-watched camera (e.g. the dome's shutter line)."""
    if isinstance(settings, OpenCvCameraSettings):
        return OpenCvCamera(settings, clock=clock)
    if isinstance(settings, Gphoto2CameraSettings):
        return Gphoto2Camera(settings, output_dir=output_dir, clock=clock, gp_module=gp_module)
    if isinstance(settings, FolderWatchSettings):
        return FolderWatchCamera(settings, clock=clock, trigger=trigger)
    raise TypeError(f"no camera driver for settings of type {type(settings).__name__}")
