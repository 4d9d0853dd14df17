"""How many bytes one image of a rig takes on disk, from what its camera config says it writes.

Why a module of its own: the start-up disk check (before the rig opens) and the controller's
check before each image must count the same bytes, and only the app layer reads a camera's
driver settings (``[camera.device]``: a RAW camera's ``decode.mode``, ``keep_jpeg``); the
controller gets the figure through :attr:`rti_rig.runtime.rig.Rig.bytes_per_image`.
"""

from __future__ import annotations

from rti_rig.app.config import LoadedRig, camera_device_settings
from rti_rig.runtime.session import estimated_bytes_per_image


def bytes_per_image(loaded: LoadedRig) -> int:
    """The bound :func:`~rti_rig.runtime.session.estimated_bytes_per_image` gives for this
    rig's camera: a RAW camera (``gphoto2``, ``folder_watch``) by its decode mode, with its
    RAW kept in the session's ``raw/`` (and the camera's JPEG with ``keep_jpeg``); any other
    camera, a full-size 16-bit RGB TIFF and its JPEG."""
    cam = loaded.config.camera
    if cam.device is None or loaded.config.backend != "hardware":
        return estimated_bytes_per_image(cam.width, cam.height)
    settings = camera_device_settings(loaded)
    decode = getattr(settings, "decode", None)
    if decode is None:  # a camera that delivers frames, not RAW files (opencv)
        return estimated_bytes_per_image(cam.width, cam.height)
    return estimated_bytes_per_image(
        cam.width,
        cam.height,
        decode.mode,
        kept_raw=True,
        kept_jpeg=bool(getattr(settings, "keep_jpeg", False)),
    )
