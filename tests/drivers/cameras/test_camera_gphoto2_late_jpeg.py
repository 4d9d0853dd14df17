"""gphoto2, RAW+JPEG: the JPEG's FILE_ADDED may come after the camera has been quiet a while
(a body still writing it).

The driver stopped collecting at the first quiet 200 ms once it had the RAW, whatever
``event_timeout_s`` said, and the late announcement was taken at the next shot as that shot's
file: with ``keep_jpeg`` the session kept shot 1's JPEG as ``raw/image_002.jpg``, each later
JPEG one light off.
"""

from __future__ import annotations

import numpy as np
from dng_spec_writer import dng, mosaic_from_rgb
from fake_gphoto2 import Body, make_module

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.cameras.gphoto2_camera import Gphoto2Camera
from rti_rig.drivers.cameras.settings import Gphoto2CameraSettings


def render(body: Body | None = None) -> bytes:
    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (32, 48, 3))
    return dng(mosaic_from_rgb(np.array(rgb), "RGGB", (0, 0, 0, 0), 4095), white=4095)


def camera(body: Body, out, **kw) -> Gphoto2Camera:
    kw.setdefault("image_format", "RAW + Large Fine JPEG")
    return Gphoto2Camera(
        Gphoto2CameraSettings(**kw),
        output_dir=out,
        clock=VirtualClock(),
        gp_module=make_module(body),
    )


def kept(frame) -> list[str]:
    return sorted(o["name"] for o in frame.metadata["originals"])


def test_a_jpeg_announced_late_is_waited_for_and_kept_with_its_own_shot(tmp_path):
    body = Body(render=render, second_file_quiet_waits=3)  # 600 ms after the RAW
    with camera(body, tmp_path, keep_jpeg=True) as cam:
        first, second = cam.capture(1 / 60), cam.capture(1 / 60)
    assert kept(first) == ["/IMG_0001.CR2", "/IMG_0001.JPG"]
    assert kept(second) == ["/IMG_0002.CR2", "/IMG_0002.JPG"]


def test_a_previous_shots_file_is_never_this_shots(tmp_path):
    # later than event_timeout_s: shot 1 goes without its JPEG (and says so); the JPEG, pending
    # when shot 2 is taken, is not shot 2's
    body = Body(render=render, second_file_quiet_waits=30)
    with camera(body, tmp_path, keep_jpeg=True, event_timeout_s=1.0) as cam:
        first, second = cam.capture(1 / 60), cam.capture(1 / 60)
    assert kept(first) == ["/IMG_0001.CR2"]
    assert any("no JPEG" in n for n in first.metadata["notices"])
    assert "/IMG_0001.JPG" not in kept(second)
    assert second.metadata["late_camera_files"] == ["/IMG_0001.JPG"]
    assert all(n.startswith("/IMG_0002") for n in second.metadata["camera_files"])


def test_without_keep_jpeg_the_raw_is_not_held_back(tmp_path):
    body = Body(render=render, second_file_quiet_waits=3)
    with camera(body, tmp_path) as cam:
        first, second = cam.capture(1 / 60), cam.capture(1 / 60)
    assert kept(first) == ["/IMG_0001.CR2"] and kept(second) == ["/IMG_0002.CR2"]
    assert second.metadata["late_camera_files"] == ["/IMG_0001.JPG"]
    assert body.calls.count("wait_for_event") <= 4  # one quiet wait a shot, one late event


def test_bodies_naming_every_shot_alike_keep_their_files(tmp_path):
    body = Body(render=render, naming="repeat")  # capt0000.CR2 + capt0000.JPG every shot
    with camera(body, tmp_path, keep_jpeg=True) as cam:
        first, second = cam.capture(1 / 60), cam.capture(1 / 60)
    assert kept(first) == kept(second) == ["/capt0000.CR2", "/capt0000.JPG"]
    assert second.metadata["late_camera_files"] == []


def test_a_body_that_keeps_reporting_property_changes_does_not_hold_a_shot(tmp_path):
    """A body that reports a property change every 20 ms when it has nothing else to say
    (GP_EVENT_UNKNOWN, as Canon bodies do): only GP_EVENT_TIMEOUT had counted as waiting or
    as quiet, so the wait for a shot's files never ended and the session hung at its first
    image. Now quiet is time with no file announced, and event_timeout_s bounds the wait."""
    clock = VirtualClock()
    body = Body(render=render, chatter_s=0.02, chatter_clock=clock)
    cam = Gphoto2Camera(
        Gphoto2CameraSettings(image_format="RAW"),
        output_dir=tmp_path,
        clock=clock,
        gp_module=make_module(body),
    )
    with cam:
        first, second = cam.capture(1 / 60), cam.capture(1 / 60)
        assert kept(first) == ["/IMG_0001.CR2"] and kept(second) == ["/IMG_0002.CR2"]
        assert clock.now() < 1.0  # each shot's wait ended after a quiet 200 ms
    # a JPEG that never comes: waited for event_timeout_s, not for ever
    body = Body(render=render, chatter_s=0.02, chatter_clock=clock)
    settings = Gphoto2CameraSettings(image_format="RAW", keep_jpeg=True, event_timeout_s=1.0)
    with Gphoto2Camera(settings, tmp_path, clock, make_module(body)) as cam:
        start = clock.now()
        frame = cam.capture(1 / 60)
    assert 1.0 <= clock.now() - start < 1.1
    assert any("no JPEG" in n for n in frame.metadata["notices"])
