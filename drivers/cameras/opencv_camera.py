"""UVC cameras through OpenCV's V4L2 backend, with every automatic control off and verified.

Why verify by reading back: ``VideoCapture.set`` returns True on many drivers even when the value
did not latch (auto exposure still on, exposure clamped). A capture is only trusted after the
camera reports the exposure that was asked for. Why drain: V4L2 queues several buffers, so the
next frame read after changing exposure was usually exposed *before* the change.

Facts used (from OpenCV's modules/videoio/src/cap_v4l.cpp): ``CAP_PROP_AUTO_EXPOSURE`` maps to the
V4L2 menu (1 = manual, 3 = aperture-priority auto) unless OPENCV_VIDEOIO_V4L_RANGE_NORMALIZED is
set; ``CAP_PROP_EXPOSURE`` is V4L2 exposure_absolute in 100 µs units; a Y16 stream comes back as
CV_16UC1 only with ``CAP_PROP_CONVERT_RGB = 0``. OpenCV maps no auto-gain control: if the camera
has one, turn it off with ``v4l2-ctl -c gain_automatic=0`` (or ``autogain``) and set ``gain``.

Safe state: idle and released (``close``). ``backend = "images"`` reads an image sequence for
dry runs and tests through the same read/drain/convert path, without camera controls.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, Protocol

import cv2
import numpy as np

from rti_rig.core.clock import Clock, SystemClock
from rti_rig.core.devices import Frame
from rti_rig.core.errors import CaptureError, DeviceError
from rti_rig.core.shell_words import pip_install
from rti_rig.drivers.cameras.image_io import to_linear_uint16
from rti_rig.drivers.cameras.raw_decode import exposure_stats
from rti_rig.drivers.cameras.settings import OpenCvCameraSettings

RAW_GREY_FOURCCS = {"Y16 ", "Y10 ", "Y12 "}
#: Grey formats OpenCV hands over as they are (one channel) only with ``CAP_PROP_CONVERT_RGB``
#: off: with it on (its default) ``convertToRgb`` in cap_v4l.cpp makes every frame 8-bit BGR
#: (a Y16 frame to its high byte, GREY by ``COLOR_GRAY2BGR``), so a grey camera's
#: session had been written as three equal colour channels (an 8-bit GREY one) or lost its
#: 16 bits (a Y16 one).
GREY_FOURCCS = RAW_GREY_FOURCCS | {"GREY"}
#: Buffers OpenCV's V4L2 backend queues unless CAP_PROP_BUFFERSIZE changes it
#: (DEFAULT_V4L_BUFFERS in modules/videoio/src/cap_v4l.cpp).
OPENCV_V4L_DEFAULT_BUFFERS = 4
#: Freshly exposed frames discarded after the queued ones, whatever the queue: the frame in
#: flight when the drain began (its exposure may have begun before the light was settled)
#: and two more while the sensor latches a new exposure at a frame boundary (UVC sensors take
#: one frame or more: realsense #11228 reports up to 5 on one body, so ``drain_frames`` can
#: ask for more). A one-buffer queue with the default 4 drained has always discarded 3.
FRESH_FRAMES_DISCARDED = 3


class VideoCaptureLike(Protocol):
    """The slice of ``cv2.VideoCapture`` this driver uses (a fake implements it in tests)."""

    def isOpened(self) -> bool: ...

    def set(self, prop: int, value: float) -> bool: ...

    def get(self, prop: int) -> float: ...

    def grab(self) -> bool: ...

    def read(self) -> tuple[bool, Any]: ...

    def release(self) -> None: ...


CaptureFactory = Callable[[int | str, int], VideoCaptureLike]


def fourcc_to_str(code: float) -> str:
    """Decode OpenCV's numeric FOURCC property into its four characters."""
    c = int(code)
    return "".join(chr((c >> (8 * i)) & 0xFF) for i in range(4))


class OpenCvCamera:
    """A UVC camera (``backend = "v4l2"``) or an image sequence (``"images"``)."""

    def __init__(
        self,
        settings: OpenCvCameraSettings,
        clock: Clock | None = None,
        capture_factory: CaptureFactory | None = None,
    ) -> None:
        self.settings = settings
        self.name = settings.name
        self._clock = clock or SystemClock()
        self._factory: CaptureFactory = capture_factory or cv2.VideoCapture
        self._cap: VideoCaptureLike | None = None
        self._frames_read = 0
        #: frames each capture drains: ``frames_to_drain``, raised at connect to the buffers
        #: the driver really queues when ``drain_frames`` is left unset
        self._drain = settings.frames_to_drain
        self.connection_info: dict[str, Any] = {}

    # -- lifecycle -------------------------------------------------------------------------
    def connect(self) -> None:
        """Open the device and put it in manual mode; raises DeviceError naming what failed."""
        if self._cap is not None:
            return
        s = self.settings
        if s.backend == "images":
            if not isinstance(s.device, str):
                raise DeviceError(
                    self.name,
                    "backend 'images' needs device = a file pattern such as 'frames/f_%03d.png'",
                    "connect",
                )
            api = cv2.CAP_IMAGES
        else:
            api = cv2.CAP_V4L2
        cap = self._factory(s.device, api)
        if not cap.isOpened():
            cap.release()
            where = f"/dev/video{s.device}" if isinstance(s.device, int) else s.device
            hint = (
                "check that the device exists (v4l2-ctl --list-devices), that you may read it "
                "(group 'video') and that no other program holds it"
                if s.backend == "v4l2"
                else "check the file pattern and that the first file exists"
            )
            raise DeviceError(self.name, f"cannot open {where} ({s.backend}): {hint}", "connect")
        self._cap = cap
        self._frames_read = 0
        try:
            if s.backend == "v4l2":
                self._configure(cap)
            else:
                self.connection_info = {"backend": "images", "controls": False}
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Release the device. Safe twice and after a failed connect."""
        cap, self._cap = self._cap, None
        if cap is not None:
            cap.release()

    def __enter__(self) -> OpenCvCamera:
        self.connect()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- configuration ---------------------------------------------------------------------
    def _set_verified(
        self, cap: VideoCaptureLike, prop: int, value: float, what: str, tol: float = 0.5
    ) -> float:
        accepted = cap.set(prop, value)
        got = cap.get(prop)
        if not accepted or abs(got - value) > tol:
            raise DeviceError(
                self.name,
                f"camera did not accept {what} = {value:g} (set returned {accepted}, reads back "
                f"{got:g}); check `v4l2-ctl -d {self.settings.device} --list-ctrls`",
                f"set {what}",
            )
        return got

    def _configure(self, cap: VideoCaptureLike) -> None:
        s = self.settings
        info: dict[str, Any] = {"backend": "v4l2", "controls": True}
        # Size first: a size change renegotiates the format, which could drop the fourcc.
        if s.width is not None:
            self._set_verified(cap, cv2.CAP_PROP_FRAME_WIDTH, s.width, "width")
        if s.height is not None:
            self._set_verified(cap, cv2.CAP_PROP_FRAME_HEIGHT, s.height, "height")
        if s.fourcc is not None:
            cap.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter_fourcc(*s.fourcc))
            got = fourcc_to_str(cap.get(cv2.CAP_PROP_FOURCC))
            if got != s.fourcc and s.require_fourcc:
                raise DeviceError(self.name, self._fourcc_refused(got), "set fourcc")
            info["fourcc"] = got
            if got in GREY_FOURCCS:
                self._set_verified(cap, cv2.CAP_PROP_CONVERT_RGB, 0, "convert_rgb")
        if s.fps is not None:
            # before the buffers: OpenCV restarts the stream for a new frame interval
            accepted = cap.set(cv2.CAP_PROP_FPS, s.fps)
            got = cap.get(cv2.CAP_PROP_FPS)
            if got <= 0 or abs(got - s.fps) > 0.01 * s.fps:
                raise DeviceError(
                    self.name,
                    f"camera did not take fps = {s.fps:g} in [camera.device] (set returned "
                    f"{accepted}, reads back {got:g}): choose a frame rate it offers for this "
                    f"format and size (`v4l2-ctl -d {s.device} --list-formats-ext`), or remove "
                    "fps",
                    "set fps",
                )
        info["buffer_size_set"] = bool(cap.set(cv2.CAP_PROP_BUFFERSIZE, s.buffer_size))
        self._drain = self._drain_for_queue(cap, info)
        fps = cap.get(cv2.CAP_PROP_FPS)
        if fps > 0:  # some drivers report none (0): the capture's time is then not known
            info["fps"] = float(fps)
        if s.toggle_auto_exposure:
            cap.set(cv2.CAP_PROP_AUTO_EXPOSURE, s.auto_exposure_auto)
        self._set_verified(
            cap, cv2.CAP_PROP_AUTO_EXPOSURE, s.auto_exposure_manual, "auto_exposure (manual)"
        )
        # Mono sensors have no white balance control: absent is fine, stuck on is not. Read
        # back whatever set returned: a driver that says yes and leaves auto white balance on
        # had passed, and each light's colour was then balanced differently.
        accepted = cap.set(cv2.CAP_PROP_AUTO_WB, 0)
        if cap.get(cv2.CAP_PROP_AUTO_WB) == 1:
            raise DeviceError(
                self.name,
                f"camera did not turn auto white balance off (set returned {accepted}, reads "
                f"back 1); try `v4l2-ctl -d {s.device} -c white_balance_automatic=0` (older "
                "kernels: white_balance_temperature_auto=0)",
                "set auto_wb",
            )
        info["auto_wb"] = cap.get(cv2.CAP_PROP_AUTO_WB)
        if s.wb_temperature_k is not None:
            self._set_verified(
                cap, cv2.CAP_PROP_WB_TEMPERATURE, s.wb_temperature_k, "wb_temperature", tol=50
            )
        if s.gain is not None:
            self._set_verified(cap, cv2.CAP_PROP_GAIN, s.gain, "gain")
        if "fourcc" in info and fourcc_to_str(cap.get(cv2.CAP_PROP_FOURCC)) != info["fourcc"]:
            raise DeviceError(
                self.name,
                f"pixel format changed from {info['fourcc']!r} while "
                "configuring; set fourcc, width and height the camera supports "
                "together (`v4l2-ctl --list-formats-ext`)",
                "verify fourcc",
            )
        width, height = cap.get(cv2.CAP_PROP_FRAME_WIDTH), cap.get(cv2.CAP_PROP_FRAME_HEIGHT)
        if width > 0 and height > 0:  # the size negotiated (VIDIOC_G_FMT), which frames have
            info["frame_size"] = [int(width), int(height)]
        self.connection_info = info
        if s.response is None and info.get("fourcc") not in RAW_GREY_FOURCCS:
            # an 8-bit stream is refused at connect, before a session lights anything
            ok, frame = cap.read()
            if ok and frame is not None:
                self._refuse_misshapen(np.asarray(frame), "connect")
                self._refuse_unset_response(np.asarray(frame))
        else:
            self._start_stream(cap)
        self.connection_info = info

    def _fourcc_refused(self, got: str) -> str:
        """Why the connect stops when the camera keeps another pixel format than ``fourcc``,
        with settings the rig config can hold.

        Why: it had said to "set fourcc = null", which TOML cannot write (it has no null): an
        omitted ``fourcc`` is the default ``"Y16 "`` again, and ``""`` is refused as not four
        characters. The format the camera delivers is named as the value to give instead, with
        the ``response`` its 8-bit frames need (or ``require_fourcc = false`` where the camera
        reports no readable format)."""
        s = self.settings
        readable = len(got) == 4 and got.isprintable() and got.strip()
        accept = (
            f'set fourcc = "{got}" (the format it delivers)'
            if readable
            else "set require_fourcc = false (to take the format it delivers)"
        )
        if got not in RAW_GREY_FOURCCS and s.response is None:
            accept += ' and response = "srgb" (or "linear" if yours is linear)'
        return (
            f"camera refused pixel format {s.fourcc!r} (delivers {got!r}); it may not offer "
            f"16-bit frames: list its formats with `v4l2-ctl -d {s.device} --list-formats-ext` "
            f"and set fourcc to one it offers in [camera.device], or {accept} in "
            "[camera.device] to accept its 8-bit gamma-encoded frames"
        )

    def _start_stream(self, cap: VideoCaptureLike) -> None:
        """Start the stream at connect, with one frame read and discarded, in the dark.

        Why: OpenCV starts a V4L2 stream (VIDIOC_STREAMON) at the first ``grab``, and a
        camera's first frame comes hundreds of milliseconds to a second after it (OpenCV issue
        #25688: "the first grab on a camera video stream is consistently several hundreds of
        milliseconds long"; linuxpy #13: about 1 s). A 16-bit stream was started by the
        session's first capture, its LED lit, a wait no lit-time check counts (it counts frame
        periods): on LEDs allowed 1.5 s it ran into the thermal guard at image 1. A camera
        that gives no frame at all is now said at connect, not with a light on."""
        if not cap.grab():
            raise DeviceError(
                self.name,
                "the camera opened but delivered no frame: check the cable and that no other "
                f"program streams from it (`v4l2-ctl -d {self.settings.device} --stream-mmap "
                "--stream-count=1`)",
                "start stream",
            )
        self._frames_read += 1

    def _drain_for_queue(self, cap: VideoCaptureLike, info: dict[str, Any]) -> int:
        """Frames to drain so that none exposed before the light settled or the exposure
        changed is kept: the buffers the driver queues, then freshly exposed frames.

        Why: a driver that refuses the buffer-size request (``set`` returns False) keeps its
        own queue, OpenCV's V4L2 default of 4 buffers or more, and ``get`` reports it; a drain
        shorter than that returned a frame exposed at the previous light's exposure, while the
        metadata said ``drained_frames = 4`` as if it were fresh. Draining just the queue is
        not enough either: the next frame is the one in flight as the drain began (uvcvideo
        fills a re-queued buffer from the next frame start, whose exposure began before), and a
        sensor latches a new exposure a frame or more late. A drain of exactly the queue had
        kept that frame, or the one after it, on a 4-buffer queue: the new light's image at
        the previous step's exposure. An unset ``drain_frames`` drains the queue and
        :data:`FRESH_FRAMES_DISCARDED` more (as a one-buffer queue with 4 drained always did);
        a set one that would keep the in-flight frame is refused, naming the key."""
        s = self.settings
        asked = s.buffer_size if info["buffer_size_set"] else None
        got = cap.get(cv2.CAP_PROP_BUFFERSIZE)
        # OpenCV reports the buffers the driver allocated (VIDIOC_REQBUFS may give more than
        # asked): an accepted request for 1 had been trusted over a read-back of 3
        queued = max(asked or 0, int(got)) if got >= 1 else asked or OPENCV_V4L_DEFAULT_BUFFERS
        info["buffers_queued"] = queued
        drain = s.frames_to_drain
        if s.drain_frames is None:
            return max(drain, queued + FRESH_FRAMES_DISCARDED)
        if drain > queued:
            return drain
        refused = (
            ""
            if info["buffer_size_set"]
            else f"the driver refused buffer_size = {s.buffer_size} (CAP_PROP_BUFFERSIZE) and "
        )
        raise DeviceError(
            self.name,
            f"{refused}{queued} buffer{' is' if queued == 1 else 's are'} queued, so "
            f"drain_frames = {s.drain_frames} in [camera.device] would keep a frame exposed "
            f"before the exposure changed or the light settled (the one in flight): set "
            f"drain_frames = {queued + 1} or more ({queued + FRESH_FRAMES_DISCARDED} leaves the "
            "sensor time to latch a new exposure), or remove it (unset, it follows the queue)",
            "set buffer_size",
        )

    def capture_time_s(self, exposure_s: float) -> tuple[float, str] | None:
        """The longest a ``capture`` of ``exposure_s`` reads frames for, and how that is
        counted, once connected; None on an image sequence or a camera reporting no frame rate.

        Why: the capture drains ``self._drain`` frames and keeps one, all with the LED lit.
        Queued frames may be read at once, but a queue the camera has not refilled since the
        last capture (the settle is shorter than the queue at the frame rate) is waited for a
        frame period a frame; each period is counted as at least the exposure (the worst case;
        :meth:`refuse_exposure` refuses a longer exposure, which a UVC camera in manual exposure
        clamps to the period). Counted as every frame read waited
        for, the worst case: the lit-time check made from the config alone counted only the
        exposure, and a 5 fps camera whose driver refused the one-buffer request held its LED
        1.6 s a capture past a ``max_on_s`` the check had passed."""
        fps = self.connection_info.get("fps")
        if self._cap is None or self.settings.backend != "v4l2" or not fps:
            return None
        period = max(1.0 / fps, exposure_s)
        frames = self._drain + 1
        queued = self.connection_info.get("buffers_queued")
        if self.settings.drain_frames is None and queued is not None:
            how = (
                f"drain_frames unset: the {queued} buffer{'s' if queued != 1 else ''} the "
                f"driver queues and {self._drain - queued} fresh"
            )
        else:
            how = f"drain_frames = {self._drain}"
        said = (
            f"{frames} frames at {fps:g} fps, {period:.3g} s each ({how}, then the one kept) "
            f"= {frames * period:.3g} s"
        )
        return frames * period, said

    def representable_exposure_s(self, exposure_s: float) -> float:
        """An exposure the camera takes exactly, in whole ``exposure_unit_s`` steps: the
        longest at or under ``exposure_s``, but never under one step, so an ``exposure_s``
        shorter than one unit gives one unit, longer than asked (the shortest the camera
        takes); any value on an image sequence, which has no controls. What ``run
        --auto-exposure`` asks for, so that a metered exposure is never refused as "not a
        whole number of units"."""
        if self.settings.backend != "v4l2":
            return exposure_s
        unit = self.settings.exposure_unit_s
        return max(1, math.floor(exposure_s / unit + 1e-9)) * unit

    def exposure_units_said(self) -> str | None:
        """The key that sets the steps :meth:`representable_exposure_s` takes, with its value
        (``exposure_unit_s = 0.0001 s in [camera.device]``); None when any exposure is taken.

        Why: a metering start moved to a whole unit was said as "(it takes whole units)",
        naming neither the unit nor the key that sets it."""
        if self.settings.backend != "v4l2":
            return None
        return f"exposure_unit_s = {self.settings.exposure_unit_s:g} s in [camera.device]"

    def shortest_exposure_s(self) -> tuple[float, str]:
        """The shortest exposure the camera takes, and what bounds it (a phrase naming the
        key): ``[camera.device] min_exposure_s``, rounded up to whole ``exposure_unit_s`` on
        v4l2.

        Why: ``run --auto-exposure`` metered within ``[camera] min_exposure_s`` alone; a
        device minimum above it (5 units of 100 µs) had a bright object metered down to a
        test shot the camera refuses ("outside the configured range"), and the run stopped,
        told of a range the user never asked the metering to leave."""
        s = self.settings
        shortest = s.min_exposure_s
        if s.backend == "v4l2":
            unit = s.exposure_unit_s
            shortest = max(1, math.ceil(shortest / unit - 1e-9)) * unit
        said = f"min_exposure_s = {s.min_exposure_s:g} s in [camera.device]"
        if not math.isclose(shortest, s.min_exposure_s, rel_tol=1e-9):
            said += f", {shortest:g} s in whole {s.exposure_unit_s:g} s units"
        return shortest, said

    def longest_exposure_s(self) -> tuple[float, str] | None:
        """The longest exposure the connected camera can take, and what bounds it (a phrase
        naming the keys to change), or None before ``connect``.

        Why: ``run --auto-exposure`` meters within ``[camera]``'s range, fixed from the config
        before the camera is open; a dark object was metered past the frame period (1/fps,
        known only once connected) or ``[camera.device] max_exposure_s``, and the run stopped
        at the metering's own test shot, told to shorten an exposure the user never chose."""
        if self._cap is None:
            return None
        s = self.settings
        fps = self.connection_info.get("fps") if s.backend == "v4l2" else None
        bound = (
            s.max_exposure_s,
            f"max_exposure_s = {s.max_exposure_s:g} s in [camera.device] (the range it refuses "
            "exposures outside)",
        )
        if fps and 1.0 / fps < bound[0]:
            lower = "set" if s.fps is None else f"lower fps = {s.fps:g} in [camera.device] to"
            bound = (
                1.0 / fps,
                f"the frame period {1.0 / fps:.4g} s of the camera's {fps:g} fps "
                "(CAP_PROP_FPS): in manual exposure a UVC camera exposes at most one period; "
                f"for longer exposures {lower} a lower fps in [camera.device] if the camera "
                f"offers one (`v4l2-ctl -d {s.device} --list-formats-ext`)",
            )
        return bound

    def exposure_problem(self, exposure_s: float) -> str | None:
        """Why ``exposure_s`` cannot be shot on the connected camera (None: it can), for
        ``rti-rig check``: what :meth:`refuse_exposure` would refuse before a session lights
        anything (a check had passed such a config)."""
        try:
            self.refuse_exposure(exposure_s, "a session would stop before its first image")
        except DeviceError as exc:
            return exc.message
        return None

    def refuse_exposure(self, exposure_s: float, before: str) -> None:
        """Refuse an exposure longer than the frame period the connected camera reports.

        Why: in manual exposure a UVC camera keeps its frame rate (auto-exposure priority,
        which may slow the stream, applies to auto modes only and is off by default), so a
        sensor asked for 0.05 s at 30 fps exposes 1/30 s, while ``exposure_absolute`` reads
        back 500 units as set. The read-back check passed, the session recorded 0.05 s and
        every image was a third darker than recorded, unsaid. The frame interval
        (``CAP_PROP_FPS``, VIDIOC_G_PARM) is what bounds the exposure. Nothing is checked on an
        image sequence or a camera reporting no frame rate. ``before`` says what was not done
        ("nothing was lit")."""
        if self._cap is None or self.settings.backend != "v4l2":
            return
        s = self.settings
        if not s.min_exposure_s <= exposure_s <= s.max_exposure_s:
            # capture refuses it, with the LED already lit (the config's [camera] range may
            # allow it: the config loader refuses only ranges that share no exposure)
            side = "shorter" if exposure_s < s.min_exposure_s else "longer"
            key = "min_exposure_s" if side == "shorter" else "max_exposure_s"
            limit = s.min_exposure_s if side == "shorter" else s.max_exposure_s
            raise DeviceError(
                self.name,
                f"exposure {exposure_s:g} s is {side} than the camera's {key} = {limit:g} s "
                f"in [camera.device] (the range it refuses exposures outside); {before}. Set "
                f"[camera] exposure_s within [{s.min_exposure_s:g}, {s.max_exposure_s:g}] s, "
                f"or change {key} in [camera.device] if the camera can take it",
                "check exposure",
            )
        not_whole = self._not_whole_units(exposure_s)
        if not_whole is not None:
            raise DeviceError(
                self.name,
                f"{not_whole}; {before}. Set [camera] exposure_s to one of those",
                "check exposure",
            )
        fps = self.connection_info.get("fps")
        if not fps:
            return
        period = 1.0 / fps
        if exposure_s <= period * (1 + 1e-6):
            return
        slowest = math.floor(1.0 / exposure_s * 1000) / 1000
        set_fps = (
            "set"
            if self.settings.fps is None
            else f"lower fps = {self.settings.fps:g} in [camera.device] to"
        )
        raise DeviceError(
            self.name,
            f"exposure {exposure_s:g} s is longer than the frame period {period:.4g} s of the "
            f"camera's {fps:g} fps (CAP_PROP_FPS): in manual exposure a UVC camera keeps its "
            "frame rate and exposes at most one period, while its exposure reads back as set, "
            f"so each image would be darker than recorded; {before}. {set_fps.capitalize()} "
            f"fps = {slowest:g} or lower in [camera.device] if the camera offers it "
            f"(`v4l2-ctl -d {self.settings.device} --list-formats-ext`), or shorten the "
            f"exposure to at most {period:.4g} s ([camera] exposure_s, max_exposure_s)",
            "check exposure",
        )

    def _refuse_misshapen(self, image: np.ndarray, operation: str) -> None:
        """Refuse a frame whose shape is not the size the camera negotiated at connect.

        Why: OpenCV 4.11.0's V4L2 backend hands every frame it does not convert to BGR (Y16,
        GREY: ``CAP_PROP_CONVERT_RGB`` off) over as one flat row of the buffer's bytes
        (opencv/opencv#27166, broken by #26224, fixed by #27193 in 4.12.0). Taken as an image,
        a 64×48 Y16 frame was a 6144×1 8-bit one: recorded, and the run then advised setting
        the camera's size to 6144×1. ``pyproject.toml`` excludes 4.11.0; another build of it
        (a distribution's package) is refused here, naming the cause."""
        size = self.connection_info.get("frame_size")
        if size is None:
            return
        width, height = size
        if image.shape[:2] == (height, width):
            return
        got = "×".join(str(n) for n in reversed(image.shape[:2]))
        fourcc = self.connection_info.get("fourcc", "its")
        if image.ndim <= 2 and min(image.shape, default=0) <= 1:
            message = (
                f"OpenCV {cv2.__version__} handed the camera's {fourcc!s} frame over as one "
                f"flat row of {image.size} {image.dtype} values, not as its {width}×{height} "
                "pixels: OpenCV 4.11.0's V4L2 backend does so with every frame it does not "
                "convert to colour (opencv/opencv#27166, fixed in 4.12.0). Install another "
                f"OpenCV ({pip_install('opencv-contrib-python-headless>=4.12')}) and run again"
            )
        else:
            message = (
                f"the camera delivered a {got} frame, not the {width}×{height} it negotiated "
                "(CAP_PROP_FRAME_WIDTH, CAP_PROP_FRAME_HEIGHT): set width and height in "
                f"[camera.device] to a size it offers (`v4l2-ctl -d {self.settings.device} "
                "--list-formats-ext`)"
            )
        raise CaptureError(self.name, message, operation)

    def _refuse_unset_response(self, image: np.ndarray) -> None:
        """An 8-bit frame with no ``response`` configured is refused, not taken as linear: such
        frames are gamma-encoded on nearly every camera, and read as linear they bias every
        fitted normal without a word (the default had been "linear")."""
        if image.dtype == np.uint8 and self.settings.response is None:
            raise DeviceError(
                self.name,
                "the camera delivers 8-bit frames, which are gamma-encoded on nearly every "
                'camera: set response = "srgb" in [camera.device] (or "linear" if yours '
                'is linear), or ask for a 16-bit format (fourcc = "Y16 ") if it offers one',
                "capture",
            )

    # -- capture ---------------------------------------------------------------------------
    def _ran_out(self) -> str:
        """Why the stream ended, as far as it can be told. For an image sequence: how many
        files were read, so that a sequence shorter than the session (or a drain that skips
        files) is told as such, not as a lost device. For a V4L2 camera that has delivered
        frames: OpenCV's grab fails once the device has gone (VIDIOC_DQBUF answers ENODEV), so
        the camera is said to have dropped off, with what to check and that the session is
        resumed once it is back (it had said "stream ended while draining frame 1 of 4" alone,
        which named neither the unplugged camera nor what to do)."""
        s = self.settings
        if s.backend != "images":
            if s.backend != "v4l2" or self._frames_read == 0:
                return ""
            where = f"/dev/video{s.device}" if isinstance(s.device, int) else str(s.device)
            if _device_node_present(where):
                # OpenCV's grab also fails on its select() timeout, the device still there:
                # the camera hung or its link reset; no unplugging was established
                why = (
                    f"{where} is still there, so the camera hung or its USB link reset: unplug "
                    "it and plug it in again"
                )
            else:
                why = (
                    f"{where} is gone: it was unplugged or dropped off the USB bus (a loose "
                    "cable, a hub, a laptop's USB power saving): check its cable and hub"
                )
            return (
                f": the camera on {where} stopped delivering frames after "
                f"{self._frames_read} read; {why}, and once it is back (v4l2-ctl "
                "--list-devices; it may return as another /dev/video number, then set "
                "[camera.device] device to it) resume the session"
            )
        how = (
            f" (drain_frames = {self._drain} in [camera.device], then one kept)"
            if s.drain_frames is not None
            else ""
        )
        return (
            f": the image sequence {s.device} ended after {self._frames_read} file"
            f"{'s' if self._frames_read != 1 else ''}; each capture reads "
            f"{self._drain + 1}{how}"
        )

    def _require_open(self) -> VideoCaptureLike:
        if self._cap is None:
            raise CaptureError(
                self.name, "camera is not connected; call connect() first", "capture"
            )
        return self._cap

    def _not_whole_units(self, exposure_s: float) -> str | None:
        """Why the camera cannot take ``exposure_s`` (not within ``exposure_tolerance`` of a
        whole number of ``exposure_unit_s``), naming the exposures either side; None if it can.

        Why: found only at the capture, with the first step's LED lit, and said as "choose a
        representable exposure", naming neither the key nor the exposures that are."""
        s = self.settings
        units = max(1, round(exposure_s / s.exposure_unit_s))
        if abs(units * s.exposure_unit_s - exposure_s) <= s.exposure_tolerance * exposure_s:
            return None
        lower = max(1, math.floor(exposure_s / s.exposure_unit_s)) * s.exposure_unit_s
        return (
            f"exposure {exposure_s:g} s is not a whole number of the camera's "
            f"{s.exposure_unit_s:g} s exposure units (exposure_unit_s in [camera.device]; "
            f"V4L2 exposure_absolute), within exposure_tolerance = {s.exposure_tolerance:g}: "
            f"the nearest it takes are {lower:g} s and {lower + s.exposure_unit_s:g} s"
        )

    def _apply_exposure(self, cap: VideoCaptureLike, exposure_s: float) -> tuple[float, float]:
        """Set the exposure, verify it reads back; returns (actual_s, units)."""
        s = self.settings
        units = max(1, round(exposure_s / s.exposure_unit_s))
        actual = units * s.exposure_unit_s
        not_whole = self._not_whole_units(exposure_s)
        if not_whole is not None:
            raise CaptureError(self.name, not_whole, "set exposure")
        accepted = cap.set(cv2.CAP_PROP_EXPOSURE, units)
        got = cap.get(cv2.CAP_PROP_EXPOSURE)
        if not accepted or abs(got - units) > max(0.5, s.exposure_tolerance * units):
            raise CaptureError(
                self.name,
                f"exposure set to {units} units ({actual:g} s) but the camera reads back {got:g} "
                f"(set returned {accepted}): auto exposure may be on or the value out of range",
                "set exposure",
            )
        return got * s.exposure_unit_s, float(units)

    def _read_checked(self, cap: VideoCaptureLike, operation: str) -> np.ndarray:
        """One frame read and checked as every frame is: delivered, of the size negotiated
        (v4l2), and 8-bit only with a ``response`` set; raises naming ``operation``."""
        ok, image = cap.read()
        if not ok or image is None:
            raise CaptureError(
                self.name,
                "no frame delivered (stream ended or device lost)" + self._ran_out(),
                operation,
            )
        self._frames_read += 1
        image = np.asarray(image)
        if self.settings.backend == "v4l2":
            self._refuse_misshapen(image, operation)
        self._refuse_unset_response(image)
        return image

    def test_shot(self) -> str:
        """Read one frame as the camera streams it (no exposure set, nothing kept) and check it
        as a capture would: its size the one negotiated, and an 8-bit frame only with a
        ``response`` set; say what it was (for ``rti-rig check``).

        Why: ``check`` took no frame of a UVC camera, and passed a config whose first capture
        was refused ("the camera delivers 8-bit frames … set response"), the dome lit."""
        try:
            image = self._read_checked(self._require_open(), "test frame")
        except CaptureError:
            raise
        except DeviceError as exc:  # said as the frame's fault, as a capture's would be
            raise CaptureError(self.name, exc.message, "test frame") from exc
        depth = "16-bit" if image.dtype == np.uint16 else "8-bit"
        height, width = image.shape[:2]
        return f"one test frame read: {width}×{height}, {depth}"

    def capture(self, exposure_s: float) -> Frame:
        """Set ``exposure_s``, drain queued frames, read one fresh frame as linear data."""
        s = self.settings
        cap = self._require_open()
        if not s.min_exposure_s <= exposure_s <= s.max_exposure_s:
            raise CaptureError(
                self.name,
                f"exposure {exposure_s:g} s outside the configured range "
                f"[{s.min_exposure_s:g}, {s.max_exposure_s:g}] s",
                "capture",
            )
        started = self._clock.now()
        if s.backend == "v4l2":
            try:  # a caller that did not check before lighting: refused before any frame
                self.refuse_exposure(exposure_s, "no frame was read")
            except DeviceError as exc:
                raise CaptureError(self.name, exc.message, "set exposure") from exc
            actual, units = self._apply_exposure(cap, exposure_s)
            gain = float(cap.get(cv2.CAP_PROP_GAIN))
            applied = True
        else:
            actual, units, applied = exposure_s, exposure_s / s.exposure_unit_s, False
            gain = float(s.gain or 0.0)
        drain = self._drain
        for i in range(drain):
            if not cap.grab():
                raise CaptureError(
                    self.name,
                    f"stream ended while draining frame {i + 1} of {drain}{self._ran_out()}",
                    "drain",
                )
            self._frames_read += 1
        image = self._read_checked(cap, "read")
        pixels, white = to_linear_uint16(
            image, s.response or "linear", s.black_level, s.white_level, order="bgr"
        )
        metadata: dict[str, Any] = {
            "camera": self.name,
            "backend": s.backend,
            "device": s.device,
            "source_file": None,
            "bit_depth": 16 if image.dtype == np.uint16 else 8,
            "response": s.response if image.dtype == np.uint8 else "linear",
            "exposure_requested_s": exposure_s,
            "exposure_units": units,
            "exposure_applied": applied,
            "gain_unit": "v4l2" if applied else "configured",
            "drained_frames": drain,
            "stream_index": self._frames_read - 1,
            "capture_started_s": started,
            "capture_finished_s": self._clock.now(),
        }
        metadata.update(self.connection_info)
        metadata.update(exposure_stats(pixels, white, 0.001))
        return Frame(
            pixels=pixels,
            exposure_s=actual,
            gain=gain,
            white_level=white,
            timestamp_s=started,
            metadata=metadata,
        )


def _device_node_present(where: str) -> bool:
    """Whether a V4L2 camera's device node exists now: a stream that stopped with it gone was
    unplugged; with it there, OpenCV's grab had timed out on a camera that hung."""
    import os

    return os.path.exists(where)
