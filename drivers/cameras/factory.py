"""Build a camera driver from validated settings (for the rig-config composition root), and
register the built-in kinds (OpenCV/UVC, python-gphoto2, a watched folder).

Why here and not in the config loader: the loader should not need to know each backend's
constructor; it validates ``[camera.device]`` with ``parse_camera_settings`` and calls
:func:`build_camera`, which finds the kind in :mod:`rti_rig.drivers.cameras.kinds`. Nothing is
opened: the controller calls ``connect()``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from rti_rig.core.clock import Clock
from rti_rig.core.devices import Camera
from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
from rti_rig.drivers.cameras.gphoto2_camera import Gphoto2Camera
from rti_rig.drivers.cameras.kinds import (
    CameraContext,
    CameraKind,
    camera_kind,
    register_camera_kind,
)
from rti_rig.drivers.cameras.opencv_camera import OpenCvCamera
from rti_rig.drivers.cameras.settings import (
    CameraSettings,
    FolderWatchSettings,
    Gphoto2CameraSettings,
    OpenCvCameraSettings,
)


def build_camera(
    settings: CameraSettings,
    clock: Clock | None = None,
    output_dir: Path | None = None,
    trigger: Callable[[float], None] | None = None,
    gp_module: Any = None,
) -> Camera:
    """The driver for ``settings`` (of any registered kind); ``output_dir`` is where a DSLR's
    downloads go (session folder), ``trigger`` fires a folder-watched camera (e.g. the dome's
    shutter line)."""
    kind = camera_kind(getattr(settings, "kind", None))
    if kind is None or not isinstance(settings, kind.settings):
        raise TypeError(f"no camera driver for settings of type {type(settings).__name__}")
    return kind.build(settings, CameraContext(clock, output_dir, trigger, gp_module))


register_camera_kind(
    CameraKind("opencv", OpenCvCameraSettings, lambda s, c: OpenCvCamera(s, clock=c.clock))
)
register_camera_kind(
    CameraKind(
        "gphoto2",
        Gphoto2CameraSettings,
        lambda s, c: Gphoto2Camera(
            s, output_dir=c.output_dir, clock=c.clock, gp_module=c.gp_module
        ),
        says_exposure_end=True,
    )
)
register_camera_kind(
    CameraKind(
        "folder_watch",
        FolderWatchSettings,
        lambda s, c: FolderWatchCamera(s, clock=c.clock, trigger=c.trigger),
        sets_exposure=False,
        says_exposure_end=True,
    )
)
