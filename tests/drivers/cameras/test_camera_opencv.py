"""OpenCV backend: a real image-sequence source, and a fake V4L2 device for the controls."""

from __future__ import annotations

import json
from collections import deque

import cv2
import numpy as np
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.core.devices import Camera
from rti_rig.core.errors import CaptureError, DeviceError
from rti_rig.drivers.cameras.opencv_camera import OpenCvCamera, fourcc_to_str
from rti_rig.drivers.cameras.settings import OpenCvCameraSettings


def write_sequence(folder, values, dtype=np.uint16, shape=(6, 8)):
    for i, v in enumerate(values):
        cv2.imwrite(str(folder / f"f_{i:03d}.png"), np.full(shape, v, dtype))
    return str(folder / "f_%03d.png")


def images_camera(pattern, **kw):
    return OpenCvCamera(
        OpenCvCameraSettings(backend="images", device=pattern, **kw), clock=VirtualClock(5.0)
    )


def test_image_sequence_16bit_frames_come_back_unchanged_after_draining(tmp_path):
    pattern = write_sequence(tmp_path, [1000, 2000, 3000, 4000, 5000, 6000])
    cam = images_camera(pattern, drain_frames=2)
    assert isinstance(cam, Camera)
    cam.connect()
    f = cam.capture(0.02)
    assert f.pixels.dtype == np.uint16 and f.pixels.shape == (6, 8)
    assert np.all(f.pixels == 3000)  # frames 0 and 1 were drained
    assert f.white_level == 65535
    assert f.exposure_s == 0.02 and f.timestamp_s == 5.0
    assert f.metadata["exposure_applied"] is False
    assert f.metadata["stream_index"] == 2 and f.metadata["bit_depth"] == 16
    json.dumps(f.metadata)  # goes into the session manifest as is
    assert np.all(cam.capture(0.02).pixels == 6000)
    with pytest.raises(CaptureError, match="stream ended while draining"):
        cam.capture(0.02)
    cam.close()
    cam.close()  # safe twice


def test_an_image_sequence_reads_one_file_a_capture_and_says_when_it_runs_out(tmp_path):
    """An image sequence has no queue of stale buffers: a dry run over one file per light had
    drained 4 files a capture by default (files 4, 9, …), ending after a fifth of its lights
    with "stream ended while draining frame 3 of 4"."""
    pattern = write_sequence(tmp_path, [1000, 2000, 3000])
    with images_camera(pattern) as cam:
        got = [int(cam.capture(0.01).pixels[0, 0]) for _ in range(3)]
        assert got == [1000, 2000, 3000]
        with pytest.raises(CaptureError) as info:
            cam.capture(0.01)
    said = str(info.value)
    assert "ended after 3 files" in said and "each capture reads 1" in said, said
    assert OpenCvCameraSettings(backend="v4l2").frames_to_drain == 4  # a camera still drains


def test_image_sequence_black_level_and_white_level(tmp_path):
    pattern = write_sequence(tmp_path, [100, 4095])
    cam = images_camera(pattern, drain_frames=0, black_level=64, white_level=4095)
    with cam:
        a = cam.capture(0.01)
        b = cam.capture(0.01)
    # scaled to full range: a session's TIFF carries no white level, and its readers take
    # 65535 as white (the sensor's 4031 had left saturation unseen and exports dark)
    assert a.white_level == 65535 and np.all(a.pixels == round(36 * 65535 / 4031))
    assert b.saturated_fraction == 1.0 and np.all(b.pixels == 65535)


def test_image_sequence_8bit_colour_is_rgb_and_linearised(tmp_path):
    img = np.zeros((4, 4, 3), np.uint8)
    img[..., 0], img[..., 1], img[..., 2] = 10, 128, 255  # B, G, R in OpenCV order
    cv2.imwrite(str(tmp_path / "c_000.png"), img)
    cv2.imwrite(str(tmp_path / "c_001.png"), img)
    pattern = str(tmp_path / "c_%03d.png")
    with images_camera(pattern, drain_frames=0, response="srgb") as cam:
        srgb = cam.capture(0.01)
        assert srgb.metadata["response"] == "srgb" and srgb.metadata["bit_depth"] == 8
    r, g, b = srgb.pixels[0, 0] / 65535
    assert r == pytest.approx(1.0)
    assert g == pytest.approx(((128 / 255 + 0.055) / 1.055) ** 2.4, abs=1e-4)
    assert b == pytest.approx(10 / 255 / 12.92, abs=1e-4)
    with images_camera(pattern, drain_frames=0, response="linear") as cam:
        lin = cam.capture(0.01)
    np.testing.assert_array_equal(lin.pixels[0, 0], [255 * 257, 128 * 257, 10 * 257])


def test_images_backend_errors(tmp_path):
    with pytest.raises(DeviceError, match="file pattern"):
        OpenCvCamera(OpenCvCameraSettings(backend="images", device=0)).connect()
    with pytest.raises(DeviceError, match="cannot open"):
        images_camera(str(tmp_path / "none_%03d.png")).connect()
    cam = images_camera(write_sequence(tmp_path, [1]))
    with pytest.raises(CaptureError, match="not connected"):
        cam.capture(0.01)
    cam.connect()
    with pytest.raises(CaptureError, match="outside the configured range"):
        cam.capture(10.0)


class FakeV4l2:
    """A UVC camera as OpenCV's V4L2 backend presents it, with a queue of stale buffers."""

    def __init__(
        self,
        formats=("YUYV", "Y16 "),
        manual_latches=True,
        exposure_latches=True,
        has_awb=False,
        awb_latches=True,
        opened=True,
        buffers=4,
    ):
        self.formats = formats
        self.manual_latches = manual_latches
        self.exposure_latches = exposure_latches
        self.has_awb = has_awb
        self.awb_latches = awb_latches
        self.opened = opened
        self.released = False
        self.log: list[tuple[int, float]] = []
        self.props = {
            cv2.CAP_PROP_FOURCC: float(cv2.VideoWriter_fourcc(*formats[0])),
            cv2.CAP_PROP_CONVERT_RGB: 1.0,
            cv2.CAP_PROP_AUTO_EXPOSURE: 3.0,
            cv2.CAP_PROP_EXPOSURE: 156.0,
            cv2.CAP_PROP_GAIN: 32.0,
            cv2.CAP_PROP_AUTO_WB: 1.0 if has_awb else 0.0,
            # a small frame (the size its frames have: a camera's frames are the size it says)
            cv2.CAP_PROP_FRAME_WIDTH: 6.0,
            cv2.CAP_PROP_FRAME_HEIGHT: 4.0,
            # OpenCV's V4L2 backend reports its own buffer count, the request refused below
            cv2.CAP_PROP_BUFFERSIZE: float(buffers),
        }
        # buffers already filled at the old exposure
        self.queue = deque(self._frame() for _ in range(buffers))

    def _size(self) -> tuple[int, int]:
        return int(self.props[cv2.CAP_PROP_FRAME_HEIGHT]), int(self.props[cv2.CAP_PROP_FRAME_WIDTH])

    def _frame(self):
        return np.full(self._size(), int(self.props[cv2.CAP_PROP_EXPOSURE]), np.uint16)

    def isOpened(self):
        return self.opened

    def set(self, prop, value):
        self.log.append((prop, float(value)))
        if prop == cv2.CAP_PROP_FOURCC:
            if fourcc_to_str(value) in self.formats:
                self.props[prop] = float(value)
            return True  # V4L2 often says yes anyway
        if prop == cv2.CAP_PROP_AUTO_EXPOSURE:
            if value == 1 and not self.manual_latches:
                return True  # claims success, stays in auto
            self.props[prop] = float(value)
            return True
        if prop == cv2.CAP_PROP_EXPOSURE:
            if self.exposure_latches and self.props[cv2.CAP_PROP_AUTO_EXPOSURE] == 1:
                self.props[prop] = float(value)
            return True
        if prop == cv2.CAP_PROP_AUTO_WB:
            if not self.has_awb:
                return False
            if self.awb_latches:
                self.props[prop] = float(value)
            return True  # claims success either way
        if prop == cv2.CAP_PROP_BUFFERSIZE:
            return False
        if prop in self.props:
            self.props[prop] = float(value)
            return True
        return False

    def get(self, prop):
        return self.props.get(prop, -1.0)

    def grab(self):
        # dequeue the oldest filled buffer; the driver refills one at the current exposure
        self.current = self.queue.popleft()
        self.queue.append(self._frame())
        return True

    def read(self):
        self.grab()
        return True, self.current

    def release(self):
        self.released = True


def v4l2_camera(fake, **kw):
    settings = OpenCvCameraSettings(device=0, **kw)
    return OpenCvCamera(settings, clock=VirtualClock(), capture_factory=lambda dev, api: fake)


def test_v4l2_connect_sets_y16_manual_exposure_and_awb_off_verifying_each():
    fake = FakeV4l2(has_awb=True)
    cam = v4l2_camera(fake, gain=8)
    cam.connect()
    props = [p for p, _ in fake.log]
    assert fake.props[cv2.CAP_PROP_CONVERT_RGB] == 0  # Y16 kept as 16 bits
    assert fourcc_to_str(fake.props[cv2.CAP_PROP_FOURCC]) == "Y16 "
    ae = [v for p, v in fake.log if p == cv2.CAP_PROP_AUTO_EXPOSURE]
    assert ae == [3.0, 1.0]  # toggle auto then manual
    assert fake.props[cv2.CAP_PROP_AUTO_WB] == 0
    assert fake.props[cv2.CAP_PROP_GAIN] == 8
    assert props.index(cv2.CAP_PROP_FOURCC) < props.index(cv2.CAP_PROP_AUTO_EXPOSURE)
    assert cam.connection_info["fourcc"] == "Y16 "


def test_auto_white_balance_that_stays_on_is_refused_though_set_said_yes():
    """The driver says yes to auto white balance off and leaves it on: only a refused set had
    been read back, so the connect passed and each light's colour was balanced anew."""
    with pytest.raises(DeviceError) as info:
        v4l2_camera(FakeV4l2(has_awb=True, awb_latches=False)).connect()
    said = str(info.value)
    assert "did not turn auto white balance off (set returned True, reads back 1)" in said
    assert "white_balance_automatic=0" in said


def test_v4l2_capture_sets_exposure_in_100us_units_and_drains_stale_buffers():
    fake = FakeV4l2()
    with v4l2_camera(fake) as cam:
        f = cam.capture(0.01)
    assert fake.props[cv2.CAP_PROP_EXPOSURE] == 100
    assert np.all(f.pixels == 100)  # exposed after the change, not a stale 156 frame
    assert f.exposure_s == pytest.approx(0.01)
    assert f.gain == 32.0 and f.metadata["exposure_applied"] is True
    assert fake.released


def test_without_draining_the_frame_is_stale():
    # Shows why draining exists: the same fake without it returns the old exposure's frame
    # (a drain shorter than the queue is refused at connect: below)
    fake = FakeV4l2()
    cam = v4l2_camera(fake, drain_frames=0)
    cam._drain_for_queue = lambda cap, info: 0  # type: ignore[method-assign]
    with cam:
        f = cam.capture(0.01)
    assert np.all(f.pixels == 156)


def test_a_refused_buffer_size_is_drained_in_full_or_a_short_drain_refused():
    """The driver refuses the one-buffer request and keeps 6 queued: 4 drained frames left a
    frame of the previous exposure, delivered as fresh ("drained_frames": 4). Unset, the drain
    follows the queue; set shorter than it, the connect is refused naming the key."""
    fake = FakeV4l2(buffers=6)
    with v4l2_camera(fake) as cam:
        f = cam.capture(0.01)
    assert np.all(f.pixels == 100), f.pixels  # exposed after the change
    # the 6 queued, then the frame in flight and two while the sensor latches the exposure
    assert f.metadata["drained_frames"] == 9 and f.metadata["buffers_queued"] == 6
    assert f.metadata["buffer_size_set"] is False
    with pytest.raises(DeviceError) as info:
        v4l2_camera(FakeV4l2(buffers=6), drain_frames=4).connect()
    said = str(info.value)
    assert "refused buffer_size = 1" in said and "6 buffers are queued" in said, said
    assert "drain_frames = 4 in [camera.device]" in said and "drain_frames = 7 or more" in said
    with pytest.raises(DeviceError, match="drain_frames = 7 or more"):  # the queue alone
        v4l2_camera(FakeV4l2(buffers=6), drain_frames=6).connect()


def test_v4l2_size_is_set_before_the_pixel_format():
    fake = FakeV4l2()
    with v4l2_camera(fake, width=320, height=240) as cam:
        assert cam.connection_info["fourcc"] == "Y16 "
    order = [p for p, _ in fake.log]
    assert order.index(cv2.CAP_PROP_FRAME_HEIGHT) < order.index(cv2.CAP_PROP_FOURCC)
    assert fake.props[cv2.CAP_PROP_FRAME_WIDTH] == 320


def test_v4l2_refused_manual_exposure_fails_at_connect_and_releases():
    fake = FakeV4l2(manual_latches=False)
    cam = v4l2_camera(fake)
    with pytest.raises(DeviceError, match="auto_exposure"):
        cam.connect()
    assert fake.released


def test_v4l2_exposure_that_does_not_read_back_is_an_error():
    fake = FakeV4l2(exposure_latches=False)
    with v4l2_camera(fake) as cam, pytest.raises(CaptureError, match="reads back 156"):
        cam.capture(0.01)


def test_v4l2_without_y16_is_refused_unless_allowed():
    fake = FakeV4l2(formats=("YUYV",))
    with pytest.raises(DeviceError, match="list-formats-ext"):
        v4l2_camera(fake).connect()
    fake = FakeV4l2(formats=("YUYV",))
    cam = v4l2_camera(fake, require_fourcc=False)
    cam.connect()
    assert fake.props[cv2.CAP_PROP_CONVERT_RGB] == 1  # 8-bit stream: conversion left on


def test_v4l2_unopenable_device_and_unrepresentable_exposure():
    with pytest.raises(DeviceError, match="/dev/video0"):
        v4l2_camera(FakeV4l2(opened=False)).connect()
    with v4l2_camera(FakeV4l2()) as cam, pytest.raises(CaptureError, match="whole number"):
        cam.capture(0.00015)  # 1.5 units of 100 µs


def test_settings_reject_unknown_keys_and_bad_fourcc():
    with pytest.raises(ValueError, match="extra"):
        OpenCvCameraSettings(exposure_unti_s=1e-4)
    with pytest.raises(ValueError, match="4 characters"):
        OpenCvCameraSettings(fourcc="Y16")


class EightBitV4l2(FakeV4l2):
    """A UVC camera that offers only YUYV: OpenCV hands over 8-bit BGR frames."""

    def _frame(self):
        return np.full((*self._size(), 3), 128, np.uint8)


def test_an_8bit_stream_without_a_response_is_refused_at_connect_not_taken_as_linear():
    """The default had been "linear": a UVC camera's gamma-encoded 8-bit frames went into the
    fit as linear light. Refused at connect (before a session lights anything), named, with
    the setting that accepts them."""
    fake = EightBitV4l2(formats=("YUYV",))
    cam = v4l2_camera(fake, fourcc=None, require_fourcc=False)
    with pytest.raises(DeviceError, match=r"8-bit frames.*response = \"srgb\""):
        cam.connect()
    fake = EightBitV4l2(formats=("YUYV",))
    with v4l2_camera(fake, fourcc=None, require_fourcc=False, response="srgb") as cam:
        frame = cam.capture(0.01)
    assert frame.metadata["response"] == "srgb"
    assert frame.pixels[0, 0, 0] == round(((128 / 255 + 0.055) / 1.055) ** 2.4 * 65535)


def test_an_8bit_image_sequence_without_a_response_is_refused(tmp_path):
    cv2.imwrite(str(tmp_path / "c_000.png"), np.full((4, 4, 3), 128, np.uint8))
    with (
        images_camera(str(tmp_path / "c_%03d.png"), drain_frames=0) as cam,
        pytest.raises(DeviceError, match="8-bit frames"),
    ):
        cam.capture(0.01)
