"""The controller: validate first, record what ran, keep every image, always go safe."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import numpy as np
import pytest
import tifffile
from conftest import REPO, SMALL_DOME, write_config

from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.core.errors import CaptureError, DeviceError, ScheduleError, SessionError
from rti_rig.core.lp_format import read_lp
from rti_rig.core.schedule import LightSchedule, LightStep
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import (
    CancelToken,
    FinishReason,
    StepCompleted,
    run_session,
)
from rti_rig.runtime.rig import Rig
from rti_rig.runtime.session import SessionFolder


def small_rig(tmp_path: Path) -> Rig:
    return build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))


class FailingCamera:
    """Wraps a camera and raises at capture number ``at`` (0-based)."""

    def __init__(self, inner, at: int, exc: BaseException) -> None:  # type: ignore[no-untyped-def]
        self.inner, self.at, self.exc, self.n = inner, at, exc, 0
        self.name = "failing camera"
        self.closed = False

    def connect(self) -> None:
        self.inner.connect()

    def close(self) -> None:
        self.closed = True
        self.inner.close()

    def capture(self, exposure_s: float):  # type: ignore[no-untyped-def]
        if self.n == self.at:
            raise self.exc
        self.n += 1
        return self.inner.capture(exposure_s)


def manifest(folder: Path) -> dict:
    return json.loads((folder / "manifest.json").read_text())


def assert_images_intact(folder: Path, count: int) -> None:
    jpgs = sorted(folder.glob("image_*.jpg"))
    tifs = sorted((folder / "linear").glob("image_*.tif"))
    assert len(jpgs) == count and len(tifs) == count
    entries = read_lp(folder / "lights.lp") if count else []
    assert [e.name for e in entries] == [p.name for p in jpgs]
    steps = manifest(folder)["steps"]
    assert len(steps) == count
    import hashlib

    for s in steps:
        for name, digest in s["sha256"].items():
            assert hashlib.sha256((folder / name).read_bytes()).hexdigest() == digest
    assert not list(folder.rglob(".*partial"))


def test_complete_session_records_what_ran(tmp_path: Path) -> None:
    rig = small_rig(tmp_path)
    schedule = plan_uniform(rig.geometry, 12)
    out = tmp_path / "s"
    result = run_session(rig, schedule, SessionFolder.create(out, len(schedule)))
    assert result.finish_reason is FinishReason.COMPLETED
    assert_images_intact(out, 12)
    m = manifest(out)
    assert m["runner"]["finish_reason"] == "completed"
    assert m["rig"]["config"]["name"] == "small"
    assert m["schedule"]["method"] == "uniform"
    assert set(m["software"]) >= {"rti_rig", "python", "numpy"}
    t = rig.loaded.config.timing
    per_step = t.light_switch_s + t.settle_s + 0.05 + t.readout_s + t.transfer_s
    assert result.rig_time_s == pytest.approx(12 * per_step, rel=1e-9)
    assert m["timing"]["rig_time_s"] == pytest.approx(result.rig_time_s)
    lp = read_lp(out / "lights.lp")
    leds = [s["led"] for s in m["steps"]]
    np.testing.assert_allclose([e.direction for e in lp], rig.geometry.directions[leds], atol=1e-6)
    assert rig.lighting.source.lit is None  # type: ignore[attr-defined]


def test_cancel_between_steps_keeps_images_and_turns_lights_off(tmp_path: Path) -> None:
    rig = small_rig(tmp_path)
    schedule = plan_uniform(rig.geometry, 12)
    cancel = CancelToken()

    def on_event(e) -> None:  # type: ignore[no-untyped-def]
        if isinstance(e, StepCompleted) and e.index == 2:
            cancel.cancel()

    out = tmp_path / "s"
    result = run_session(
        rig, schedule, SessionFolder.create(out, 12), cancel=cancel, on_event=on_event
    )
    assert result.finish_reason is FinishReason.CANCELLED
    assert len(result.records) == 3
    assert_images_intact(out, 3)
    assert manifest(out)["runner"]["finish_reason"] == "cancelled"
    dome = rig.lighting.source  # type: ignore[attr-defined]
    assert dome.lit is None and dome.history[-1][1] is None


@pytest.mark.parametrize(
    ("exc", "reason"),
    [
        (CaptureError("cam", "camera busy", "capture"), "error"),
        (KeyboardInterrupt(), "interrupted"),
    ],
)
def test_failing_capture_keeps_images_and_lights_off(
    tmp_path: Path, exc: BaseException, reason: str
) -> None:
    rig = small_rig(tmp_path)
    rig.camera = FailingCamera(rig.camera, 4, exc)
    schedule = plan_uniform(rig.geometry, 12)
    out = tmp_path / "s"
    with pytest.raises(type(exc)):
        run_session(rig, schedule, SessionFolder.create(out, 12))
    assert_images_intact(out, 4)
    m = manifest(out)
    assert m["runner"]["finish_reason"] == reason
    assert m["runner"]["steps_done"] == 4
    assert rig.lighting.source.lit is None  # type: ignore[attr-defined]
    assert rig.camera.closed  # type: ignore[attr-defined]


def test_failing_light_and_failing_teardown_are_reported(tmp_path: Path) -> None:
    rig = small_rig(tmp_path)
    dome = rig.lighting.source  # type: ignore[attr-defined]
    real_light, real_off = dome.light, dome.all_off
    calls = {"n": 0}

    def light(index: int, intensity: float = 1.0) -> None:
        calls["n"] += 1
        if calls["n"] == 3:
            raise DeviceError("dome", f"no ack for LED {index}", f"light {index}")
        real_light(index, intensity)

    def all_off() -> None:
        real_off()
        if calls["n"] >= 3:
            raise DeviceError("dome", "port gone", "all off")

    dome.light, dome.all_off = light, all_off
    out = tmp_path / "s"
    with pytest.raises(DeviceError, match="no ack for LED"):
        run_session(rig, plan_uniform(rig.geometry, 6), SessionFolder.create(out, 6))
    assert_images_intact(out, 2)
    runner = manifest(out)["runner"]
    assert "no ack for LED" in runner["error"]
    assert any("port gone" in f for f in runner["teardown_failures"])


class ResizingCamera:
    """Wraps a camera; from capture number ``at`` (0-based) on, its frames are half the size
    (the camera's image size changed mid-session, or another camera's file was picked up)."""

    def __init__(self, inner, at: int) -> None:  # type: ignore[no-untyped-def]
        self.inner, self.at, self.n = inner, at, 0
        self.name = "resizing camera"

    def connect(self) -> None:
        self.inner.connect()

    def close(self) -> None:
        self.inner.close()

    def capture(self, exposure_s: float):  # type: ignore[no-untyped-def]
        import dataclasses

        frame = self.inner.capture(exposure_s)
        self.n += 1
        if self.n <= self.at:
            return frame
        half = frame.pixels[::2, ::2].copy()
        return dataclasses.replace(frame, pixels=half)


def test_a_frame_of_another_size_stops_the_session_and_is_kept_aside(tmp_path: Path) -> None:
    """Image 4 of another size had been written into the session as if nothing were wrong:
    the run said complete, and no tool could use the session (its images differ in shape)."""
    rig = small_rig(tmp_path)
    rig.camera = ResizingCamera(rig.camera, 3)
    schedule = plan_uniform(rig.geometry, 6)
    out = tmp_path / "s"
    with pytest.raises(CaptureError, match=r"image 4 came back .*but this session's images are"):
        run_session(rig, schedule, SessionFolder.create(out, 6))
    assert_images_intact(out, 3)
    assert manifest(out)["runner"]["finish_reason"] == "error"
    assert rig.lighting.source.lit is None  # type: ignore[attr-defined]
    kept = list((out / "recovered").rglob("image_004.tif"))
    assert len(kept) == 1  # the frame is not lost, only kept out of the session
    # labelled as the session's linear TIFFs are, then why it is not one (it said only why)
    pages = []
    for tif in (kept[0], out / "linear" / "image_001.tif"):
        with tifffile.TiffFile(tif) as f:
            page = f.pages.first
            pages.append((page.description, page.tags.get(34675) and page.tags[34675].value))
    assert pages[0][0].startswith(pages[1][0] + "; not image 4 of the session"), pages
    assert pages[0][1] == pages[1][1] is not None, pages
    # a resume on a camera that gives another size than the images on disk stops the same way
    rig = small_rig(tmp_path)
    rig.camera = ResizingCamera(rig.camera, 0)
    folder = SessionFolder.reopen(out)
    with pytest.raises(CaptureError, match=r"image 4 came back"):
        run_session(rig, schedule, folder)
    assert_images_intact(out, 3)


def test_validation_happens_before_anything_moves(tmp_path: Path) -> None:
    rig = small_rig(tmp_path)
    good = plan_uniform(rig.geometry, 3)
    bad = LightSchedule((*good.steps, LightStep(direction=(0, 0, 1), led=40)))
    out = tmp_path / "s"
    folder = SessionFolder.create(out, len(bad))
    with pytest.raises(ScheduleError) as info:
        run_session(rig, bad, folder)
    assert "step 4" in str(info.value) and "LED 40 does not exist" in str(info.value)
    assert rig.lighting.source.history == []  # type: ignore[attr-defined]
    assert not list(out.glob("image_*"))
    mismatched = LightSchedule((LightStep(direction=(0, 0, 1), led=0),))
    with pytest.raises(ScheduleError, match="another dome layout"):
        run_session(rig, mismatched, SessionFolder.create(tmp_path / "t", 1))


def test_never_writes_into_a_non_empty_folder(tmp_path: Path) -> None:
    out = tmp_path / "s"
    out.mkdir()
    (out / "keep.jpg").write_bytes(b"precious")
    with pytest.raises(SessionError, match="not empty") as refused:
        SessionFolder.create(out, 3)
    assert "--resume" not in str(refused.value)  # no session there to resume
    assert (out / "keep.jpg").read_bytes() == b"precious"
    (out / "manifest.json").write_text("{}")
    with pytest.raises(SessionError, match=f"rti-rig run --resume {out}"):
        SessionFolder.create(out, 3)


def test_image_write_refuses_to_overwrite(tmp_path: Path) -> None:
    rig = small_rig(tmp_path)
    folder = SessionFolder.create(tmp_path / "s", 2)
    (folder.root / "linear").mkdir(parents=True)  # create() writes nothing; begin() would
    (folder.root / "image_001.jpg").write_bytes(b"earlier capture")
    rig.camera.connect()
    frame = rig.camera.capture(0.05)
    fields = {
        "planned_direction": (0.0, 0.0, 1.0),
        "actual_direction": (0.0, 0.0, 1.0),
        "led": None,
        "rig_start_s": 0.0,
        "light_s": 0.0,
        "settle_s": 0.0,
        "capture_s": 0.0,
    }
    with pytest.raises(SessionError, match="refusing to overwrite"):
        folder.write_step(0, frame, fields)
    assert (folder.root / "image_001.jpg").read_bytes() == b"earlier capture"


def test_arm_session_records_reached_directions_and_parks(
    tmp_path: Path, arm_config_path: Path
) -> None:
    text = (
        arm_config_path.read_text()
        .replace("width = 512", "width = 48")
        .replace("height = 512", "height = 48")
    )
    rig = build_rig(load_rig_config(write_config(tmp_path, text)))
    schedule = plan_uniform(rig.geometry, 10)
    out = tmp_path / "s"
    result = run_session(rig, schedule, SessionFolder.create(out, 10))
    assert result.finish_reason is FinishReason.COMPLETED
    arm = rig.lighting.carrier  # type: ignore[attr-defined]
    assert not arm.lamp_on
    assert arm.joints_deg == pytest.approx((0.0, 45.0), abs=0.1)
    steps = manifest(out)["steps"]
    for s in steps:
        angle = np.degrees(
            np.arccos(np.clip(np.dot(s["planned_direction"], s["actual_direction"]), -1, 1))
        )
        assert 0.0 <= angle < 0.1  # quantised to servo ticks, never far off
    zenith = LightSchedule((LightStep(direction=(0, 0, 1)),))
    with pytest.raises(ScheduleError, match="keep-out cone"):
        run_session(rig, zenith, SessionFolder.create(tmp_path / "z", 1))


@pytest.mark.parametrize("park_on_emergency", [False, True])
def test_arm_emergency_stop_follows_parking_policy(
    tmp_path: Path, arm_config_path: Path, park_on_emergency: bool
) -> None:
    from rti_rig.runtime.controller import EmergencyStop

    text = arm_config_path.read_text().replace("width = 512", "width = 32")
    text = text.replace("height = 512", "height = 32")
    text = text.replace(
        "default_lights = 24",
        f"default_lights = 24\npark_on_emergency_stop = {str(park_on_emergency).lower()}",
    )
    rig = build_rig(load_rig_config(write_config(tmp_path, text)))
    rig.camera = FailingCamera(rig.camera, 3, EmergencyStop(signal.SIGTERM))
    out = tmp_path / "s"
    with pytest.raises(EmergencyStop):
        run_session(rig, plan_uniform(rig.geometry, 8), SessionFolder.create(out, 8))
    arm = rig.lighting.carrier  # type: ignore[attr-defined]
    assert not arm.lamp_on
    parked = arm.joints_deg == pytest.approx((0.0, 45.0), abs=0.1)
    assert parked is park_on_emergency
    m = manifest(out)
    assert m["runner"]["finish_reason"] == "emergency-stop"
    assert_images_intact(out, 3)


@pytest.mark.parametrize("park_on_emergency", [False, True])
def test_emulated_dynamixel_arm_stays_put_after_an_emergency_stop_unless_told(
    tmp_path: Path, park_on_emergency: bool
) -> None:
    """The real driver's close must not park behind the policy's back (it once did)."""
    from rti_rig.runtime.controller import EmergencyStop

    text = (REPO / "rig_configs" / "simulated_arm.toml").read_text()
    text = text.replace("width = 256", "width = 32").replace("height = 256", "height = 32")
    text = text.replace('transport = "pty"', 'transport = "inprocess"')  # no real-time thread
    text = text.replace(
        "default_lights = 24",
        f"default_lights = 24\npark_on_emergency_stop = {str(park_on_emergency).lower()}",
    )
    rig = build_rig(load_rig_config(write_config(tmp_path, text)))
    rig.camera = FailingCamera(rig.camera, 3, EmergencyStop(signal.SIGTERM))
    with rig, pytest.raises(EmergencyStop):
        run_session(rig, plan_uniform(rig.geometry, 8), SessionFolder.create(tmp_path / "s", 8))
    arm = rig.lighting.carrier  # type: ignore[attr-defined]
    ticks = tuple(round(v) for v in rig.emulator.joint_positions().values())  # type: ignore[attr-defined]
    park = arm.kin.ticks_of_pose(0.0, 10.0)
    assert (max(abs(a - b) for a, b in zip(ticks, park, strict=True)) <= 2) is park_on_emergency
    assert not arm.lamp_is_on


def test_simulated_dslr_frames_go_through_the_raw_decode_path(tmp_path: Path) -> None:
    """scene.raw = true: every frame is a DNG decoded by rawpy, and the session still works."""
    text = SMALL_DOME.replace("seed = 3", "seed = 3\nraw = true")
    rig = build_rig(load_rig_config(write_config(tmp_path, text)))
    rig.camera.connect()
    rig.lighting.connect()
    rig.lighting.set(plan_uniform(rig.geometry, 1).steps[0])
    frame = rig.camera.capture(0.05)
    assert frame.metadata["source"] == "simulated-raw"
    assert frame.pixels.shape == (64, 64, 3) and frame.pixels.dtype == np.uint16
    assert "underexposed_fraction" in frame.metadata  # measured by the rawpy decode path
    out = tmp_path / "s"
    rig2 = build_rig(load_rig_config(write_config(tmp_path, text, "raw.toml")))
    result = run_session(rig2, plan_uniform(rig2.geometry, 6), SessionFolder.create(out, 6))
    assert result.finish_reason is FinishReason.COMPLETED
    assert_images_intact(out, 6)


def test_an_emergency_stop_during_an_image_s_commit_leaves_it_listed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A real SIGTERM (the CLI's handler raises EmergencyStop) arriving while step 4's files are
    written, on another thread: the commit finishes first, so every image on disk is in
    lights.lp and the manifest. It had stopped between the files and the journal line, leaving
    an image on disk that lights.lp did not list (found with a double Ctrl-C through the
    command line)."""
    import signal
    import threading
    import time

    import rti_rig.runtime.session as session_module
    from rti_rig.runtime.controller import EmergencyStop

    real_write = session_module.write_srgb_jpeg
    calls = {"n": 0}

    bystander = threading.Event()
    other = threading.Thread(target=bystander.wait, daemon=True)  # as BLAS's or an emulator's
    other.start()

    def write_and_get_killed(path, pixels):  # type: ignore[no-untyped-def]
        calls["n"] += 1
        if calls["n"] == 4:
            # delivered to another thread, as the kernel may deliver a signal sent to the
            # process: a signal mask in the main thread alone held nothing
            signal.pthread_kill(other.ident, signal.SIGTERM)
            time.sleep(0.05)  # the handler would run here, in the main thread, unless held
        return real_write(path, pixels)

    def on_sigterm(signum, frame):  # type: ignore[no-untyped-def]
        raise EmergencyStop(signal.SIGTERM)

    monkeypatch.setattr(session_module, "write_srgb_jpeg", write_and_get_killed)
    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        rig = small_rig(tmp_path)
        out = tmp_path / "s"
        completed: list[int] = []

        def on_event(event):  # type: ignore[no-untyped-def]
            if isinstance(event, StepCompleted):
                completed.append(event.index)

        with pytest.raises(EmergencyStop):
            run_session(
                rig,
                plan_uniform(rig.geometry, 8),
                SessionFolder.create(out, 8),
                on_event=on_event,
            )
    finally:
        signal.signal(signal.SIGTERM, previous)
        bystander.set()
    # the progress shown counts every image kept (it had been one short: "3/8", 4 kept)
    assert completed == [0, 1, 2, 3]
    runner = manifest(out)["runner"]
    assert runner["finish_reason"] == "emergency-stop"
    assert_images_intact(out, 4)
    # counted as done in this run too (the stop acted before the count: 3 of 4 were said)
    assert runner["steps_done_this_run"] == runner["steps_done"] == 4


class ExposingWrapper:
    """Wraps a camera as an ``ExposingCamera`` whose exposure is over ``ends_after_s`` after it
    fires (None: it cannot tell); records, with the rig's clock, what happens when."""

    def __init__(self, inner, clock, ends_after_s, log) -> None:  # type: ignore[no-untyped-def]
        self.inner, self.clock, self.ends_after_s, self.log = inner, clock, ends_after_s, log
        self.name = "exposing camera"
        self._exposure: float | None = None

    def connect(self) -> None:
        self.inner.connect()

    def close(self) -> None:
        self.inner.close()

    def capture(self, exposure_s: float):  # type: ignore[no-untyped-def]
        raise AssertionError("an ExposingCamera is driven through expose() and collect()")

    def expose(self, exposure_s: float) -> float | None:
        self.log.append(("expose", self.clock.now()))
        self._exposure = exposure_s
        if self.ends_after_s is None:
            return None
        return self.clock.now() + self.ends_after_s

    def collect(self):  # type: ignore[no-untyped-def]
        self.log.append(("collect", self.clock.now()))
        assert self._exposure is not None
        return self.inner.capture(self._exposure)


@pytest.mark.parametrize("ends_after_s", [0.8, None])
def test_the_light_goes_off_when_the_camera_says_its_exposure_is_over(
    tmp_path: Path, ends_after_s: float | None
) -> None:
    """A DSLR's download and decode, a tethered file's transfer, happened with the LED lit: the
    object got seconds more light per image and a slow file ran into the thermal limit. Now
    the light goes off at the end the camera gives, before the frame is collected; a camera
    that cannot tell keeps it on until the frame is in."""
    rig = small_rig(tmp_path)
    log: list[tuple[str, float]] = []
    rig.camera = ExposingWrapper(rig.camera, rig.clock, ends_after_s, log)
    lighting_off = rig.lighting.off

    def off() -> None:
        log.append(("off", rig.clock.now()))
        lighting_off()

    rig.lighting.off = off  # type: ignore[method-assign]
    result = run_session(
        rig, plan_uniform(rig.geometry, 3), SessionFolder.create(tmp_path / "s", 3)
    )
    assert result.finish_reason is FinishReason.COMPLETED
    assert log[0][0] == "off" and len(log) == 1 + 3 * 3  # the session's opening all-off first
    steps = [log[i : i + 3] for i in range(1, len(log), 3)]
    for step in steps:
        names = [name for name, _ in step]
        if ends_after_s is None:
            assert names == ["expose", "collect", "off"]
        else:
            assert names == ["expose", "off", "collect"]
            assert step[1][1] - step[0][1] == pytest.approx(ends_after_s)
