"""A UVC camera streaming as a real one does, behind OpenCV's V4L2 backend, on a virtual clock.

Modelled on the published behaviour, not on our driver:

* OpenCV's ``cap_v4l.cpp``: the first ``grab`` queues every buffer and starts the stream
  (``VIDIOC_STREAMON``); each ``grab`` gives the buffer it handed out last back to the driver
  (``VIDIOC_QBUF``), then takes the oldest filled one (``VIDIOC_DQBUF``), waiting for one if
  none is filled; ``read`` is ``grab`` then retrieve. ``CAP_PROP_BUFFERSIZE`` is the number
  of buffers (4 by default); a driver may refuse another count.
* The camera exposes frames continuously at its frame rate whether or not the host reads
  them; uvcvideo fills a buffer only from the start of a frame (it waits for the frame-ID bit
  to toggle, so a buffer queued mid-frame gets the next frame), and a frame that finds no
  queued buffer is dropped: a full queue holds the *oldest* frames.
* In manual exposure the frame rate stays constant (UVC auto-exposure priority off, its
  default; Microsoft's KSPROPERTY_CAMERACONTROL_AUTO_EXPOSURE_PRIORITY: "if the frame rate is
  30 fps, the exposure time cannot exceed 33 ms"): a longer exposure is clamped to the frame
  period, and ``exposure_absolute`` still reads back as set. ``CAP_PROP_FPS`` sets the frame
  rate (VIDIOC_S_PARM: the nearest the camera offers) and reads back the one in use.
* A rolling shutter: row ``r`` of frame ``k`` is read out at ``k·P + r·R/H`` (``P`` the frame
  period, ``R`` the readout time) after an exposure of ``e`` seconds ending then; the frame is
  delivered once its last row is read. A new exposure value takes effect ``latency_frames``
  frame periods after it is set (sensors latch it at a frame boundary).

Each row's value is ``scale`` × the light integrated over that row's own exposure, so a frame
exposed partly under another light (or partly dark) shows it row by row.

The pixel format (``pixel_format``: ``"Y16 "``, ``"GREY"`` or ``"YUYV"``, the only one the
camera offers) comes back as OpenCV's ``cap_v4l.cpp`` (repository opencv/opencv) gives it.
What is verified, and from which source:

* Read in two stored versions of ``modules/videoio/src/cap_v4l.cpp``: an IplImage-era one
  (commit 02b49759, before #26224) and a 4.11-era one (commit dc2214ef, with #26224's
  ``retrieveFrame`` that #27193 fixed in 4.12.0).
* ``CAP_PROP_CONVERT_RGB`` on (``open`` sets ``convert_rgb = true``): ``convertToRgb`` makes
  every frame 8-bit BGR, GREY by ``cvtColor(Mat(size, CV_8UC1), COLOR_GRAY2BGR)`` and YUYV
  by ``cvtColor(Mat(size, CV_8UC2), COLOR_YUV2BGR_YUYV)`` (both versions). Y16: the 4.11-era
  source takes each pixel's high byte (``extractChannel(Mat(size, CV_8UC2), temp, 1)``, the
  little-endian sample's second byte: ``v >> 8``, truncated), then ``COLOR_GRAY2BGR``; this
  fake does that. The IplImage-era source rounded instead (``convertTo(CV_8U, 1.0/256)``);
  it had been modelled here, from memory, for every release. Which release switched is not
  verified (likely with #18498, Y16_BE): the two differ by at most 1 in 8 bits.
* ``CAP_PROP_CONVERT_RGB`` off, the IplImage-era source (``v4l2_create_frame``'s
  ``!convert_rgb`` switch, then ``retrieveFrame`` copying the buffer into that header): Y16
  as CV_16UC1 (rows × cols), GREY as CV_8UC1 (rows × cols), YUYV as CV_8UC2 (rows × cols × 2,
  the bytes Y0 U Y1 V as sent, so channel 1 alternates U and V). This fake gives those.
* ``opencv_4_11 = True``, the 4.11-era source: with ``CAP_PROP_CONVERT_RGB`` off,
  ``retrieveFrame`` wraps the buffer as ``Mat(Size(min(length, bytesused), 1), CV_8U)``: one
  row of its bytes, 1 × bytesused (numpy ``(1, bytesused)`` uint8), whatever the format
  (opencv/opencv#27166: 16-bit frames "returned as a flattened array"; broken by #26224 in
  4.11.0, fixed by #27193). Converted frames are as above.
* ``set(CAP_PROP_FOURCC, other)`` (both versions): ``palette = value`` then ``v4l2_reset``,
  whose ``autosetup_capture_mode_v4l2`` falls back through its ``try_order`` to a format the
  camera takes: ``set`` answers True and the camera's own format stays. This fake does so.
* ``set(CAP_PROP_CONVERT_RGB, 0)`` answers True; ``1`` answers ``convertableToRgb()`` (True
  for these three formats).

Assumed, not read: that 4.12's #27193 gives the unconverted shapes of the IplImage-era
source again (its description: "Restored image initialization process for non-BGR data");
OpenCV 5.x (this venv's cv2) is not verified at all. The pixel values are the model's own:
the sensor's 16-bit light values for Y16, their high byte as the luma of GREY and YUYV, and
no chroma (U = V = 128) in YUYV.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from rti_rig.core.clock import VirtualClock


@dataclass
class _Buffer:
    state: str = "queued"  # queued (the driver's), filling, done, held (the application's)
    queued_at: float = 0.0
    frame: int | None = None
    done_at: float = 0.0


class LightHistory:
    """The light on the object as a function of time (piecewise constant), on ``clock``."""

    def __init__(self, clock: VirtualClock) -> None:
        self.clock = clock
        self.changes: list[tuple[float, float]] = [(-math.inf, 0.0)]

    def set(self, level: float) -> None:
        self.changes.append((self.clock.now(), level))

    def integral(self, t0: float, t1: float) -> float:
        total = 0.0
        for i, (start, level) in enumerate(self.changes):
            end = self.changes[i + 1][0] if i + 1 < len(self.changes) else math.inf
            lo, hi = max(start, t0), min(end, t1)
            if hi > lo:
                total += level * (hi - lo)
        return total


class BufferedUvcStream:
    """``cv2.VideoCapture(device, CAP_V4L2)`` on a Y16 UVC camera (see the module docstring)."""

    def __init__(
        self,
        light: LightHistory,
        *,
        fps: float = 10.0,
        readout_s: float = 0.05,
        rows: int = 8,
        cols: int = 4,
        buffers: int = 4,
        buffer_size_accepted: bool = True,
        min_buffers: int = 1,
        latency_frames: int = 1,
        scale: float = 100_000.0,
        exposure_units: float = 100.0,
        frame_rates: tuple[float, ...] | None = None,
        start_latency_s: float = 0.0,
        pixel_format: str = "Y16 ",
        opencv_4_11: bool = False,
    ) -> None:
        self.light = light
        self.pixel_format = pixel_format
        self.opencv_4_11 = opencv_4_11
        #: the first frame's readout begins this long after STREAMON (OpenCV #25688: "the
        #: first grab on a camera video stream is consistently several hundreds of ms long")
        self.start_latency_s = start_latency_s
        self.clock = light.clock
        #: the frame rates the camera offers for its format and size (VIDIOC_ENUM_FRAMEINTERVALS);
        #: VIDIOC_S_PARM picks the nearest, and CAP_PROP_FPS then reads that one back
        self.frame_rates = frame_rates or (fps,)
        self.period = 1.0 / fps
        self.readout_s = readout_s
        self.rows, self.cols = rows, cols
        self.accept_buffer_size = buffer_size_accepted
        #: VIDIOC_REQBUFS may allocate more buffers than asked; OpenCV then reports those
        self.min_buffers = min_buffers
        self.latency_frames = latency_frames
        self.scale = scale
        self.buffers = [_Buffer() for _ in range(buffers)]
        self.streaming_from: float | None = None
        self.next_frame = 0
        self.held: _Buffer | None = None
        #: (time set, exposure units): the exposure control's history
        self.exposures: list[tuple[float, float]] = [(-math.inf, exposure_units)]
        self.props = {
            cv2.CAP_PROP_FOURCC: float(cv2.VideoWriter_fourcc(*pixel_format)),
            cv2.CAP_PROP_CONVERT_RGB: 1.0,
            cv2.CAP_PROP_AUTO_EXPOSURE: 3.0,
            cv2.CAP_PROP_EXPOSURE: exposure_units,
            cv2.CAP_PROP_GAIN: 0.0,
            cv2.CAP_PROP_AUTO_WB: 0.0,
            cv2.CAP_PROP_FRAME_WIDTH: float(cols),
            cv2.CAP_PROP_FRAME_HEIGHT: float(rows),
            cv2.CAP_PROP_BUFFERSIZE: float(buffers),
            cv2.CAP_PROP_FPS: fps,
        }
        #: every frame handed to the application: (frame number, its rows' exposure windows)
        self.delivered: list[tuple[int, list[tuple[float, float]]]] = []

    # -- the camera and the driver ---------------------------------------------------------
    def _exposure_s(self, k: int) -> float:
        """The exposure frame ``k`` was taken at: the value set ``latency_frames`` periods
        before the frame period its exposure began in."""
        t0 = self.streaming_from or 0.0  # frame k is read out from t0 + k·P (the clock's)
        latch = t0 + (k - 1 - self.latency_frames) * self.period
        units = [u for t, u in self.exposures if t <= latch][-1]
        # manual exposure keeps the frame rate (auto-exposure priority is off): a longer
        # exposure is clamped to the frame period, while exposure_absolute reads back as set
        return min(units * 1e-4, self.period)

    def _row_windows(self, k: int) -> list[tuple[float, float]]:
        e = self._exposure_s(k)
        t0 = self.streaming_from or 0.0
        return [
            (
                t0 + k * self.period + r * self.readout_s / self.rows - e,
                t0 + k * self.period + r * self.readout_s / self.rows,
            )
            for r in range(self.rows)
        ]

    def _run_until(self, now: float) -> None:
        """Frames whose readout began by ``now`` go into a buffer queued before they began,
        or are dropped; buffers whose frame is read out by ``now`` are done."""
        assert self.streaming_from is not None
        while self.streaming_from + self.next_frame * self.period <= now:
            k = self.next_frame
            start = self.streaming_from + k * self.period
            free = [b for b in self.buffers if b.state == "queued" and b.queued_at <= start]
            if free:
                b = min(free, key=lambda b: b.queued_at)
                b.state, b.frame, b.done_at = "filling", k, start + self.readout_s
            self.next_frame += 1
        for b in self.buffers:
            if b.state == "filling" and b.done_at <= now:
                b.state = "done"

    def _dequeue(self) -> _Buffer:
        while True:
            now = self.clock.now()
            self._run_until(now)
            done = [b for b in self.buffers if b.state == "done"]
            if done:
                b = min(done, key=lambda b: b.done_at)
                b.state = "held"
                return b
            pending = [b.done_at for b in self.buffers if b.state == "filling"]
            assert self.streaming_from is not None
            next_start = self.streaming_from + self.next_frame * self.period
            self.clock.sleep(max(min([*pending, next_start]) - now, 1e-9))

    def _pixels(self, k: int) -> np.ndarray:
        rows = [self.scale * self.light.integral(a, b) for a, b in self._row_windows(k)]
        col = np.clip(np.round(rows), 0, 65535).astype(np.uint16)
        return np.repeat(col[:, None], self.cols, axis=1)

    # -- VideoCapture ----------------------------------------------------------------------
    def isOpened(self) -> bool:
        return True

    def set(self, prop: int, value: float) -> bool:
        if prop == cv2.CAP_PROP_BUFFERSIZE:
            if not self.accept_buffer_size:
                return False
            count = max(int(value), self.min_buffers)
            self.buffers = [_Buffer() for _ in range(count)]
            self.props[prop] = float(count)
            return True
        if prop == cv2.CAP_PROP_FPS:
            if self.streaming_from is not None:
                return False  # not modelled: the driver sets it at connect, before streaming
            rate = min(self.frame_rates, key=lambda r: abs(r - value))
            self.period, self.props[prop] = 1.0 / rate, float(rate)
            return True
        if prop == cv2.CAP_PROP_EXPOSURE:
            if self.props[cv2.CAP_PROP_AUTO_EXPOSURE] != 1:
                return True
            self.exposures.append((self.clock.now(), float(value)))
        if prop == cv2.CAP_PROP_FOURCC and value != self.props[prop]:
            return True  # its one pixel format only (set returns True, the format stays)
        if prop in self.props:
            self.props[prop] = float(value)
            return True
        return False

    def get(self, prop: int) -> float:
        return self.props.get(prop, -1.0)

    def grab(self) -> bool:
        now = self.clock.now()
        if self.streaming_from is None:  # the first grab queues every buffer, STREAMON
            self.streaming_from = now + self.start_latency_s
            for b in self.buffers:
                b.state, b.queued_at = "queued", now
        if self.held is not None:  # VIDIOC_QBUF of the buffer handed out last
            self._run_until(now)
            self.held.state, self.held.queued_at, self.held.frame = "queued", now, None
        self.held = self._dequeue()
        return True

    def read(self) -> tuple[bool, np.ndarray]:
        self.grab()
        assert self.held is not None and self.held.frame is not None
        k = self.held.frame
        self.delivered.append((k, self._row_windows(k)))
        frame = self._retrieve(self._pixels(k))
        if self.opencv_4_11 and self.props[cv2.CAP_PROP_CONVERT_RGB] == 0:
            # the buffer's bytes (little-endian, as V4L2 Y16 is) as one row
            frame = np.frombuffer(frame.astype(frame.dtype.newbyteorder("<")).tobytes(), np.uint8)
            frame = frame.reshape(1, -1)
        return True, frame

    def _retrieve(self, light16: np.ndarray) -> np.ndarray:
        """The frame as OpenCV hands it over for the camera's pixel format (module docstring):
        the sensor's 16-bit light values, 8-bit (their high byte) for GREY and YUYV."""
        convert = self.props[cv2.CAP_PROP_CONVERT_RGB] != 0
        if self.pixel_format == "Y16 ":
            if not convert:
                return light16
            # extractChannel(…, 1): the high byte of each little-endian sample, then GRAY2BGR
            high = (light16 >> 8).astype(np.uint8)
            return cv2.cvtColor(high, cv2.COLOR_GRAY2BGR)
        luma = (light16 >> 8).astype(np.uint8)
        if self.pixel_format == "GREY":
            return cv2.cvtColor(luma, cv2.COLOR_GRAY2BGR) if convert else luma
        assert self.pixel_format == "YUYV", self.pixel_format
        packed = np.empty((*luma.shape, 2), np.uint8)  # Y0 U Y1 V: grey light, no chroma
        packed[..., 0] = luma
        packed[..., 1] = 128
        return cv2.cvtColor(packed, cv2.COLOR_YUV2BGR_YUYV) if convert else packed

    def release(self) -> None:
        """STREAMOFF and the buffers freed (OpenCV's release: VIDIOC_STREAMOFF, then
        VIDIOC_REQBUFS with count 0): a reopened stream starts again at its first frame, into
        buffers of its own. The frame count had carried on from the last stream, so a reopened
        camera's first frame came that many periods after STREAMON (1.5 s after a metering's
        30 frames at 20 fps)."""
        self.streaming_from = None
        self.next_frame = 0
        self.held = None
        self.buffers = [_Buffer() for _ in self.buffers]
