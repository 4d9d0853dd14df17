"""Master dark frames: several shots with every light off, averaged.

Why: a long exposure's thermal signal and fixed-pattern offsets add to every RTI image equally
and bias the fitted reflectance in the shadows. Take darks at the session exposure, with the
lights off, and subtract the master with ``raw_decode.subtract_dark`` after each capture.
"""

from __future__ import annotations

from rti_rig.core.devices import Camera, DiscreteLightSource, Frame
from rti_rig.drivers.cameras.raw_decode import average_frames


def capture_master_dark(
    camera: Camera,
    exposure_s: float,
    count: int = 4,
    lights: DiscreteLightSource | None = None,
) -> Frame:
    """Turn ``lights`` off (if given), take ``count`` frames, return their mean."""
    if count < 1:
        raise ValueError("count must be at least 1")
    if lights is not None:
        lights.all_off()
    frames = [camera.capture(exposure_s) for _ in range(count)]
    master = average_frames(frames)
    master.metadata["dark_count"] = count
    return master
