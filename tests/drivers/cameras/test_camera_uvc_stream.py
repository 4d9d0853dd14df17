"""A UVC camera streaming continuously, its buffers queued (tests/fake_uvc.py), under lights
switched on the session's clock: every frame a capture returns was exposed, every row of it,
wholly under its own light and at its own exposure."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from fake_uvc import BufferedUvcStream, LightHistory

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.cameras.opencv_camera import OpenCvCamera
from rti_rig.drivers.cameras.settings import OpenCvCameraSettings
from rti_rig.runtime.controller import shoot_lit

#: (light level, exposure s) per step: each light and exposure differs from the last
STEPS = [(1.0, 0.05), (0.5, 0.08), (0.8, 0.02), (0.3, 0.09), (0.6, 0.05)]


class Lights:
    """The rig's lighting as the controller drives it, recorded on the light history."""

    def __init__(self, light: LightHistory) -> None:
        self.light = light

    def off(self) -> None:
        self.light.set(0.0)


def shoot(stream: BufferedUvcStream, settle_s: float, **settings: object) -> list:
    """The controller's steps: light set, settled, captured (shoot_lit), light off."""
    clock = stream.clock
    cam = OpenCvCamera(
        OpenCvCameraSettings(device=0, **settings),
        clock=clock,
        capture_factory=lambda dev, api: stream,
    )
    rig = SimpleNamespace(camera=cam, lighting=Lights(stream.light))
    frames = []
    with cam:
        for level, exposure in STEPS:
            stream.light.set(level)
            lit_at = clock.now()
            clock.sleep(settle_s)
            frame = shoot_lit(rig, exposure)  # type: ignore[arg-type]
            frames.append((lit_at, clock.now(), level, exposure, frame))
            clock.sleep(0.3)  # the step's bookkeeping, the next light's move
    return frames


@pytest.mark.parametrize(
    "buffers, accepted, latency, min_buffers",
    [(1, True, 1, 1), (4, False, 1, 1), (6, False, 2, 1), (1, True, 2, 1), (1, True, 2, 3)],
    ids=[
        "one-buffer",
        "refused-4-queued",
        "refused-6-queued-slow-latch",
        "one-buffer-slow-latch",
        "one-asked-three-allocated",
    ],
)
def test_every_frame_is_exposed_wholly_under_its_own_light(buffers, accepted, latency, min_buffers):
    """A driver that refuses the one-buffer request keeps its queue (OpenCV's default 4): the
    drain emptied the queue and kept the first frame read after it, the one in flight as the
    light settled (its exposure began before the light came on) and, the new exposure latched
    a frame late, shot at the previous step's exposure. A driver that accepts one buffer and
    allocates three (OpenCV reports them) had been drained as if it queued one."""
    stream = BufferedUvcStream(
        LightHistory(VirtualClock()),
        buffers=buffers,
        buffer_size_accepted=accepted,
        latency_frames=latency,
        min_buffers=min_buffers,
    )
    frames = shoot(stream, settle_s=0.0)
    assert len(stream.delivered) == len(STEPS)
    for (lit_at, off_at, level, exposure, frame), (_, rows) in zip(
        frames, stream.delivered, strict=True
    ):
        for start, end in rows:  # every row exposed while its own light was on
            assert lit_at <= start and end <= off_at, (lit_at, start, end, off_at)
            assert end - start == pytest.approx(exposure)
        expected = round(stream.scale * level * exposure)
        assert abs(frame.pixels.astype(int) - expected).max() <= 1, (frame.pixels[:, 0], expected)
        assert frame.exposure_s == pytest.approx(exposure)
