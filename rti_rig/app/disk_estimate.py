"""How many bytes one image of a rig takes on disk, from what its camera config says it writes.

Why a module of its own: the start-up disk check (before the rig opens) and the controller's
check before each image must count the same bytes, and only the app layer reads a camera's
driver settings (``[camera.device]``: a RAW camera's ``decode.mode``, ``keep_jpeg``); the
controller gets the figure through :attr:`rti_rig.runtime.rig.Rig.bytes_per_image`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from rti_rig.app.config import LoadedRig, camera_device_settings, rig_geometry
from rti_rig.runtime.session import estimated_bytes_per_image


def bytes_per_image(loaded: LoadedRig) -> int:
    """The bound :func:`~rti_rig.runtime.session.estimated_bytes_per_image` gives for this
    rig's camera: a RAW camera (``gphoto2``, ``folder_watch``) by its decode mode, with its
    RAW kept in the session's ``raw/`` (and the camera's JPEG with ``keep_jpeg``); any other
    camera, a full-size 16-bit RGB TIFF and its JPEG; a replay's, plus its largest recorded
    file, which the session keeps a copy of in ``raw/``."""
    cam = loaded.config.camera
    return _bytes_for(loaded, cam.width, cam.height)


def size_from_frame(loaded: LoadedRig) -> Callable[[int, int], tuple[int, int, int]]:
    """A function of a delivered frame's width and height giving the ``[camera]`` width and
    height it implies (a RAW camera decoded at ``"half"`` delivers half the sensor's) and the
    bound on one image's files for that size, as :func:`bytes_per_image` counts them.

    Why: ``[camera] width``/``height`` default to 512 x 512 and are never checked against a
    real camera, so the disk check before a session counted a 24 MP camera's images as
    0.26 MP; the controller compares the first real frame with them and checks the disk again
    (:attr:`rti_rig.runtime.rig.Rig.size_from_frame`)."""
    half = _decode_mode(loaded) == "half"

    def implied(width: int, height: int) -> tuple[int, int, int]:
        w, h = (2 * width, 2 * height) if half else (width, height)
        return w, h, _bytes_for(loaded, w, h)

    return implied


def _decode_mode(loaded: LoadedRig) -> str | None:
    """A hardware RAW camera's ``decode.mode``; None for a camera that delivers frames."""
    if loaded.config.camera.device is None or loaded.config.backend != "hardware":
        return None
    decode = getattr(camera_device_settings(loaded), "decode", None)
    return None if decode is None else str(decode.mode)


def _bytes_for(loaded: LoadedRig, width: int, height: int) -> int:
    """:func:`bytes_per_image` for a sensor of ``width`` x ``height``."""
    mode = _decode_mode(loaded)
    if mode is None:  # a camera that delivers frames, not RAW files (opencv), or a dry run
        return estimated_bytes_per_image(width, height) + _recorded_file_bytes(loaded)
    settings = camera_device_settings(loaded)
    return estimated_bytes_per_image(
        width,
        height,
        mode,
        kept_raw=True,
        kept_jpeg=bool(getattr(settings, "keep_jpeg", False)),
    )


def _recorded_file_bytes(loaded: LoadedRig) -> int:
    """A replay rig's largest recorded file (and a file's overhead), which each step copies
    whole into the session's ``raw/``; 0 for any other rig.

    Why: a replay's session keeps its recorded files byte for byte (a 16-bit TIFF source as
    large as the session's own TIFF); uncounted, a disk that cannot hold them was let
    through, to fill mid-session."""
    if loaded.config.backend != "replay":
        return 0
    from rti_rig.core.lp_format import image_path

    folder = Path(loaded.path).parent
    largest = 0
    for name in rig_geometry(loaded).names:
        try:
            largest = max(largest, image_path(folder, name).stat().st_size)
        except OSError:  # a missing file is refused by the run's image check, not here
            continue
    return largest + 16_384
