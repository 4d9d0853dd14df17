"""A UVC camera streaming continuously, its buffers queued (tests/fake_uvc.py), under lights
switched on the session's clock: every frame a capture returns was exposed, every row of it,
wholly under its own light and at its own exposure."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import cv2
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from fake_uvc import BufferedUvcStream, LightHistory
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import SystemClock, VirtualClock
from rti_rig.core.errors import CaptureError, DeviceError
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


def _uvc_dome_config(tmp_path: Path, max_on_s: float = 1.0) -> Path:
    """The shipped 48-LED dome with a UVC camera, LEDs that may stay lit 1 s at a time: the
    config's own check passes (settle 0.1 + exposure 0.05 + readout 0.05 + transfer 0.05 +
    all-off 0.02 = 0.27 s)."""
    text = (CONFIGS / "example_dome_48.toml").read_text()
    text = text.replace('"example_dome_48.lp"', f'"{CONFIGS / "example_dome_48.lp"}"')
    text = text.replace("max_on_s = 8.0", f"max_on_s = {max_on_s}")
    text = text.replace("exposure_s = 0.125", "exposure_s = 0.05")
    text = text.replace("width = 6000\nheight = 4000", "width = 4\nheight = 8")
    text = text[: text.index("[camera.device]")] + (
        '[camera.device]\nkind = "opencv"\ndevice = 0\n\n[timing]\nlight_switch_s = 0.02\n'
        "settle_s = 0.1\nreadout_s = 0.05\ntransfer_s = 0.05\n"
    )
    cfg = tmp_path / "uvc_dome.toml"
    cfg.write_text(text)
    return cfg


@pytest.mark.pty
@pytest.mark.parametrize("fps, fits", [(5.0, False), (20.0, True)], ids=["5fps", "20fps"])
def test_a_uvc_drain_longer_than_max_on_s_is_refused_before_any_led_lights(
    tmp_path, monkeypatch, fps, fits
):
    """`rti-rig run` on a dome whose LEDs may stay lit 1 s, with a 5 fps UVC camera whose
    driver refused the one-buffer request (4 queued): each capture reads 8 frames (the queue,
    3 fresh, the one kept), 1.6 s with the LED lit. The config's check counted the exposure
    only, and the run lit LED 0 and stopped at the thermal guard ("LED 0 stayed on 1.555 s,
    beyond max_on_s = 1 s; raise max_on_s or shorten settle and exposure"). Now it is refused
    once the camera is connected, before any LED, naming the camera, the keys and figures; a
    20 fps camera (8 frames, 0.4 s) runs. The LEDs may stay lit 1.5 s here, not 1 s: the
    20 fps run is timed on the real clock of a pty session (0.62 s lit a step), and a loaded
    machine must keep inside the guard."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    stream = BufferedUvcStream(
        LightHistory(SystemClock()),  # type: ignore[arg-type]  # the session's own clock
        fps=fps,
        buffers=4,
        buffer_size_accepted=False,
    )
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    said = " ".join(r.output.split())
    lit = [e for e in firmware.history if e.what == "lit"]
    if fits:
        assert r.exit_code == 0, said
        assert len(lit) == 4
        return
    assert r.exit_code == 2, said
    assert not lit, lit  # no LED was lit
    assert "uvc-camera" in said and "8 frames at 5 fps, 0.2 s each" in said, said
    assert "the 4 buffers the driver queues and 3 fresh" in said, said
    assert "= 1.82 s, beyond max_on_s = 1.5 s" in said and str(cfg) in said.replace(" ", ""), said
    assert "timing.settle_s 0.1" in said and "nothing was lit" in said, said
    assert "Traceback" not in said and not list(out.glob("*.jpg"))


def _metered_run(tmp_path, monkeypatch, cfg, stream):  # type: ignore[no-untyped-def]
    """`rti-rig run CFG --lights 4 --auto-exposure` on the shipped dome's emulator, the UVC
    camera being STREAM: the exit code, the output on one line, the session folder and the
    firmware's history (what it lit), for the metering tests below."""
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", "4", "--auto-exposure"]
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, [*args, "--no-verdict"])
    return r.exit_code, " ".join(r.output.split()), out, firmware.history


@pytest.mark.pty
@pytest.mark.parametrize("max_on_s", [1.5, 8.0], ids=["lit-limit-1.5s", "lit-limit-8s"])
def test_a_uvc_metering_chooses_no_exposure_past_the_cameras_frame_period(
    tmp_path, monkeypatch, max_on_s
):
    """`run --auto-exposure` with a 20 fps UVC camera (period 0.05 s) and a dark object: the
    metering's range came from the config alone, fixed before the camera was open, so it
    reached for the longest exposure the LEDs' lit time allows (0.78 s at max_on_s = 1 s,
    7.7 s at 8 s), and the run stopped at its own test shot, telling the user to shorten an
    exposure they never chose ("metering stopped before its test shot at …: … beyond max_on_s"
    or "… is longer than the frame period"). Once the camera is connected its frame period
    bounds the metering: the exposure is fixed at 0.05 s, a warning names the camera, the
    frame rate and the key to lower, and the session runs, each LED lit within max_on_s."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=max_on_s)
    stream = BufferedUvcStream(
        LightHistory(SystemClock()),  # type: ignore[arg-type]  # no light reaches it: dark
        fps=20.0,
        buffers=4,
        buffer_size_accepted=False,
    )
    code, said, out, history = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert "Exposure fixed at 0.05 s" in said, said
    assert "longest the camera uvc-camera can take" in said, said
    assert "20 fps (CAP_PROP_FPS)" in said and "lower fps in [camera.device]" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    assert all(s["exposure_s"] == pytest.approx(0.05) for s in manifest["steps"])
    assert (
        max(
            t
            for shots in manifest["schedule"]["provenance"]["exposure"]["test_exposures_by_light_s"]
            for t in shots
        )
        <= 0.05 + 1e-9
    )
    assert "Traceback" not in said and "stayed on" not in said, said
    assert len([e for e in history if e.what == "lit"]) >= 4 + 4


@pytest.mark.pty
def test_a_uvc_metering_asks_only_for_exposures_in_the_cameras_units(tmp_path, monkeypatch):
    """`run --auto-exposure` on a bright object with a UVC camera set in 100 µs units: the
    metering stepped its saturated preview down 4 times at a time (0.05, 0.0125, 0.0031 s)
    and asked for 0.000775 s, which the camera refuses as "not a whole number of 0.0001 s
    units …; choose a representable exposure": the run stopped, the user told to choose an
    exposure they never chose. Each test exposure is now rounded down to whole units, and
    the session's exposure is one of them."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    light = LightHistory(SystemClock())  # type: ignore[arg-type]
    light.set(1.0)  # bright whatever LED is lit: 0.05 s saturates 76 times over
    stream = BufferedUvcStream(light, fps=20.0, scale=1e8)
    code, said, out, _ = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert "whole number" not in said and "Traceback" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    evidence = manifest["schedule"]["provenance"]["exposure"]
    shot = [t for shots in evidence["test_exposures_by_light_s"] for t in shots]
    chosen = [s["exposure_s"] for s in manifest["steps"]]
    for t in [*shot, *chosen]:
        assert t / 1e-4 == pytest.approx(round(t / 1e-4), abs=1e-6), (t, shot, chosen)
    assert chosen[0] == pytest.approx(0.0005), said  # 0.0006 s × headroom 1.25 would clip


@pytest.mark.pty
def test_a_uvc_exposure_longer_than_the_frame_period_is_refused_before_any_led_lights(
    tmp_path, monkeypatch
):
    """`rti-rig run` at exposure_s = 0.05 s with a 30 fps UVC camera: in manual exposure the
    camera keeps its frame rate and exposes 1/30 s, while exposure_absolute reads back 500
    units as set. The run recorded 0.05 s for images exposed 0.033 s; it is now refused once
    the camera is connected, before any LED, naming the camera, the keys and the frame rate to
    set. With fps = 20 in [camera.device] (offered by the camera) it runs, each kept frame
    exposed the 0.05 s recorded."""
    cfg = _uvc_dome_config(tmp_path)
    stream = BufferedUvcStream(
        LightHistory(SystemClock()),  # type: ignore[arg-type]  # the session's own clock
        fps=30.0,
        frame_rates=(30.0, 20.0, 15.0),
    )
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", "4", "--no-verdict"]
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, args)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert not [e for e in firmware.history if e.what == "lit"]
    assert "uvc-camera" in said and "exposure 0.05 s is longer than the frame period" in said
    assert "30 fps" in said and "fps = 20 or lower in [camera.device]" in said, said
    assert "[camera] exposure_s" in said and "nothing was lit" in said, said
    assert "Traceback" not in said and not out.exists()

    cfg.write_text(cfg.read_text().replace('kind = "opencv"\n', 'kind = "opencv"\nfps = 20\n'))
    stream = BufferedUvcStream(
        LightHistory(SystemClock()),  # type: ignore[arg-type]
        fps=30.0,
        frame_rates=(30.0, 20.0, 15.0),
    )
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, r.output
    assert len([e for e in firmware.history if e.what == "lit"]) == 4
    kept = stream.delivered[-4:]
    assert all(b - a == pytest.approx(0.05) for _, rows in kept for a, b in rows), kept


@pytest.mark.pty
def test_an_exposure_not_in_the_cameras_units_is_refused_before_any_led_lights(
    tmp_path, monkeypatch
):
    """`[camera] exposure_s = 0.00125` on a UVC camera set in 100 µs units (12.5 units, 4 %
    from the nearest whole one, past exposure_tolerance = 2 %): `rti-rig check` passed, and
    `rti-rig run` lit LED 0 and stopped at its first capture with "choose a representable
    exposure", naming neither the key nor an exposure the camera takes. Both now refuse it
    before any LED lights, naming [camera] exposure_s and 0.0012 s and 0.0013 s."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    cfg.write_text(cfg.read_text().replace("exposure_s = 0.05\n", "exposure_s = 0.00125\n", 1))
    stream = BufferedUvcStream(LightHistory(SystemClock()), fps=20.0)  # type: ignore[arg-type]
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert not [e for e in firmware.history if e.what == "lit"], said
    assert "exposure 0.00125 s is not a whole number" in said, said
    assert "0.0012 s and 0.0013 s" in said and "[camera] exposure_s" in said, said
    assert "nothing was lit" in said and "Traceback" not in said, said
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code != 0 and "RESULT: FAIL" in said, said
    assert "camera: uvc-camera connected (no image taken), but FAILED" in said, said
    assert "0.0012 s and 0.0013 s" in said, said


@pytest.mark.pty
def test_a_uvc_streams_start_up_is_waited_for_at_connect_not_under_a_lit_led(tmp_path, monkeypatch):
    """A UVC camera whose first frame comes 1.2 s after the stream starts (OpenCV #25688:
    hundreds of ms on Logitech webcams; about 1 s in linuxpy #13). A 16-bit stream was started
    by the session's first capture, with LED 0 lit, and the run stopped at the thermal guard
    ("LED 0 stayed on …, beyond max_on_s = 1.5 s"). The stream is now started at connect, in
    the dark: every LED is lit about 0.6 s."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    stream = BufferedUvcStream(
        LightHistory(SystemClock()),  # type: ignore[arg-type]
        fps=20.0,
        start_latency_s=1.2,
    )
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", "4", "--no-verdict"]
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, args)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert len([e for e in firmware.history if e.what == "lit"]) == 4, said


def test_a_frame_rate_the_camera_does_not_offer_is_refused_at_connect_naming_the_key():
    stream = BufferedUvcStream(LightHistory(VirtualClock()), fps=30.0, frame_rates=(30.0, 15.0))
    cam = OpenCvCamera(
        OpenCvCameraSettings(device=0, fps=20.0),
        clock=stream.clock,
        capture_factory=lambda dev, api: stream,
    )
    with pytest.raises(DeviceError) as info:
        cam.connect()
    said = str(info.value)
    assert "fps = 20 in [camera.device]" in said and "reads back 15" in said
    assert "--list-formats-ext" in said


def test_a_capture_not_checked_before_lighting_is_refused_before_a_frame_is_read():
    """A caller that did not check (a script driving the camera): refused before any frame,
    never recorded at an exposure the sensor did not take."""
    stream = BufferedUvcStream(LightHistory(VirtualClock()), fps=30.0)
    cam = OpenCvCamera(
        OpenCvCameraSettings(device=0), clock=stream.clock, capture_factory=lambda d, a: stream
    )
    with cam, pytest.raises(CaptureError, match="longer than the frame period"):
        cam.capture(0.05)
    assert not stream.delivered
    with cam:
        assert cam.capture(0.03).exposure_s == pytest.approx(0.03)


@pytest.mark.pty
def test_a_uvc_metering_at_30fps_warns_at_the_longest_whole_units_exposure(tmp_path, monkeypatch):
    """`run --auto-exposure` with a 30 fps UVC camera in 100 µs units and a dark object: the
    longest exposure it takes is 333 units, 0.0333 s, just under the frame period 1/30 s. The
    warning compared the chosen exposure with 1/30 s itself, which whole units never reach, so
    it never fired and the dark object was shot dark unsaid; it now compares with the longest
    exposure in whole units."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    cfg.write_text(cfg.read_text().replace("exposure_s = 0.05\n", "exposure_s = 0.02\n", 1))
    stream = BufferedUvcStream(LightHistory(SystemClock()), fps=30.0)  # type: ignore[arg-type]
    code, said, _, _ = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert "Exposure fixed at 0.0333 s" in said, said
    assert "longest the camera uvc-camera can take" in said, said
    assert "30 fps (CAP_PROP_FPS)" in said and "Traceback" not in said, said


@pytest.mark.pty
def test_a_configured_exposure_not_in_units_is_only_a_start_for_auto_exposure(
    tmp_path, monkeypatch
):
    """`[camera] exposure_s = 0.00125` (12.5 units of 100 µs) with `run --auto-exposure`: the
    metering replaces it and asks only for whole units, yet the run refused it before any
    LED lit ("not a whole number"). It is now the metering's start, rounded down to 0.0012 s;
    without --auto-exposure it is still refused (the test above)."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    cfg.write_text(cfg.read_text().replace("exposure_s = 0.05\n", "exposure_s = 0.00125\n", 1))
    light = LightHistory(SystemClock())  # type: ignore[arg-type]
    light.set(1.0)
    stream = BufferedUvcStream(light, fps=20.0, scale=1e6)
    code, said, out, _ = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert "whole number" not in said and "Traceback" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    shot = manifest["schedule"]["provenance"]["exposure"]["test_exposures_by_light_s"]
    assert shot[0][0] == pytest.approx(0.0012), shot


@pytest.mark.pty
@pytest.mark.parametrize("start_s", [0.05, 0.0002], ids=["start-above", "start-below-device-min"])
def test_a_uvc_metering_chooses_no_exposure_under_the_devices_min_exposure_s(
    tmp_path, monkeypatch, start_s
):
    """`run --auto-exposure` on a very bright object with `[camera.device] min_exposure_s =
    0.00045` above `[camera]`'s 0.0001: the metering's range came from `[camera]` alone, so it
    stepped a saturated preview down to 0.0001 s, which the camera refuses ("outside the
    configured range"), and the run stopped; a `[camera] exposure_s` under the device's minimum
    stopped it at the first test shot. The metering now goes no shorter than the device's
    minimum in whole units (0.0005 s), starts there if asked to start below it, and a warning
    names the key that bound it."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    text = cfg.read_text().replace("exposure_s = 0.05\n", f"exposure_s = {start_s}\n", 1)
    cfg.write_text(text.replace('kind = "opencv"\n', 'kind = "opencv"\nmin_exposure_s = 0.00045\n'))
    light = LightHistory(SystemClock())  # type: ignore[arg-type]
    light.set(1.0)
    stream = BufferedUvcStream(light, fps=20.0, scale=1e9)  # 0.0005 s saturates 7 times over
    code, said, out, _ = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert "outside the configured range" not in said and "Traceback" not in said, said
    assert "Exposure fixed at 0.0005 s" in said, said
    assert "shortest the camera uvc-camera can take" in said, said
    assert "min_exposure_s = 0.00045 s in [camera.device], 0.0005 s in whole" in said, said
    assert "its test shot there saturated 100.00% of pixels (limit 0.10%)" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    evidence = manifest["schedule"]["provenance"]["exposure"]
    shot = [t for shots in evidence["test_exposures_by_light_s"] for t in shots]
    assert min(shot) == pytest.approx(0.0005), shot
    assert all(s["exposure_s"] == pytest.approx(0.0005) for s in manifest["steps"])


@pytest.mark.pty
def test_check_says_an_exposure_not_in_units_is_a_start_for_auto_exposure(tmp_path, monkeypatch):
    """`[camera] exposure_s = 0.00125` (12.5 units of 100 µs): `run --auto-exposure` takes it
    as its metering's start (0.0012 s), but `rti-rig check` refused it with no word of that,
    so a user about to meter was told the rig failed. The refusal now says run
    --auto-exposure would start at 0.0012 s and names `check --auto-exposure`, which checks
    the rig for that run and passes it."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    cfg.write_text(cfg.read_text().replace("exposure_s = 0.05\n", "exposure_s = 0.00125\n", 1))
    stream = BufferedUvcStream(LightHistory(SystemClock()), fps=20.0)  # type: ignore[arg-type]
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "0.0012 s and 0.0013 s" in said, said
    assert "run --auto-exposure would take exposure_s only as its metering's start" in said
    assert "(at 0.0012 s, which the camera takes)" in said, said
    assert "rti-rig check --auto-exposure checks the rig for that" in said, said
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg), "--auto-exposure"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    assert "camera: uvc-camera connected (one test frame read: " in said, said
    assert "FAILED" not in said and "Traceback" not in said, said


@pytest.mark.pty
def test_an_exposure_under_the_devices_min_exposure_s_is_refused_before_any_led_lights(
    tmp_path, monkeypatch
):
    """`[camera] exposure_s = 0.0002` with `[camera.device] min_exposure_s = 0.00045`: the
    config loads (`[camera]`'s own range allows it), and `rti-rig run` lit LED 0 and stopped
    at its first capture ("outside the configured range"). It is now refused once the camera
    is connected, before any LED lights, naming both keys; `rti-rig check` fails it too."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    text = cfg.read_text().replace("exposure_s = 0.05\n", "exposure_s = 0.0002\n", 1)
    cfg.write_text(text.replace('kind = "opencv"\n', 'kind = "opencv"\nmin_exposure_s = 0.00045\n'))
    stream = BufferedUvcStream(LightHistory(SystemClock()), fps=20.0)  # type: ignore[arg-type]
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert not [e for e in firmware.history if e.what == "lit"], said
    assert "exposure 0.0002 s is shorter than the camera's min_exposure_s = 0.00045 s" in said
    assert "[camera] exposure_s" in said and "nothing was lit" in said, said
    assert "Traceback" not in said, said
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    assert "shorter than the camera's min_exposure_s = 0.00045 s" in said, said


@pytest.mark.pty
def test_a_metering_start_above_the_devices_max_exposure_s_is_lowered_to_it(tmp_path, monkeypatch):
    """`run --auto-exposure` with `[camera] exposure_s = 0.05` and `[camera.device]
    max_exposure_s = 0.02`: exposure_s is only where the metering starts (docs/cameras.md), and
    a start under the device's minimum was raised to it, but one above its maximum was refused
    ("longer than the camera's max_exposure_s"), exit 2. The start is now lowered to the
    device's longest, the run says so, and `rti-rig check --auto-exposure` passes the rig."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    cfg.write_text(
        cfg.read_text().replace('kind = "opencv"\n', 'kind = "opencv"\nmax_exposure_s = 0.02\n')
    )
    light = LightHistory(SystemClock())  # type: ignore[arg-type]
    light.set(1.0)
    stream = BufferedUvcStream(light, fps=20.0)
    code, said, out, _ = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert "longer than the camera's max_exposure_s" not in said and "Traceback" not in said
    assert "longer than the camera uvc-camera can take" in said, said
    assert "the metering started at 0.02 s" in said, said
    assert "max_exposure_s = 0.02 s in [camera.device]" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    shots = manifest["schedule"]["provenance"]["exposure"]["test_exposures_by_light_s"]
    assert max(t for s in shots for t in s) <= 0.02 + 1e-9, shots
    assert all(s["exposure_s"] <= 0.02 + 1e-9 for s in manifest["steps"])
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg), "--auto-exposure"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "RESULT: PASS" in said, said
    # without --auto-exposure exposure_s is the exposure itself: still refused, naming the key
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "longer than the camera's max_exposure_s = 0.02 s" in said, said


def _min_exposure_at_start(tmp_path: Path, device: str = "") -> Path:
    """The UVC dome with `[camera] min_exposure_s = exposure_s = 0.00125` (12.5 units of
    100 µs), and ``device`` added to `[camera.device]`."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    text = cfg.read_text().replace("exposure_s = 0.05\n", "exposure_s = 0.00125\n", 1)
    text = text.replace("min_exposure_s = 0.000125\n", "min_exposure_s = 0.00125\n", 1)
    cfg.write_text(text.replace('kind = "opencv"\n', f'kind = "opencv"\n{device}'))
    return cfg


@pytest.mark.pty
def test_the_metering_starts_where_check_judges_in_whole_units_inside_both_ranges(
    tmp_path, monkeypatch
):
    """`[camera] min_exposure_s = exposure_s = 0.00125` on a camera of 0.0001 s units: the
    start was decided twice, check judging 0.0012 s (the camera's units, not [camera]'s
    range) and the run clamping again into [camera]'s range unrounded, so the metering's first
    test shot was 0.00125 s, which the camera cannot take exactly. One decision now: the
    first whole unit inside both ranges, 0.0013 s, for the run and for check alike."""
    cfg = _min_exposure_at_start(tmp_path)
    light = LightHistory(SystemClock())  # type: ignore[arg-type]
    light.set(1.0)
    stream = BufferedUvcStream(light, fps=20.0, scale=1e6)
    code, said, out, _ = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert "whole number" not in said and "Traceback" not in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    shots = manifest["schedule"]["provenance"]["exposure"]["test_exposures_by_light_s"]
    assert shots[0][0] == pytest.approx(0.0013), shots
    assert all(abs(t / 0.0001 - round(t / 0.0001)) < 1e-6 for s in shots for t in s), shots
    assert min(t for s in shots for t in s) >= 0.00125, shots
    # the start moved by [camera]'s range and the camera's units is said, as one moved by the
    # camera's own range is (it was taken silently)
    assert (
        "[camera] exposure_s = 0.00125 s is not an exposure the camera uvc-camera takes "
        "exactly (it takes whole units of exposure_unit_s = 0.0001 s in [camera.device]) and "
        "the one it takes under it is shorter than "
        "[camera] min_exposure_s = 0.00125 s: the metering started at 0.0013 s instead"
    ) in said, said
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg), "--auto-exposure"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0 and "RESULT: PASS" in said, said


@pytest.mark.pty
def test_a_metering_start_rounded_to_the_cameras_units_is_said(tmp_path, monkeypatch):
    """`run --auto-exposure` with `[camera] exposure_s = 0.00125` (12.5 units of 100 µs):
    the metering starts at 0.0012 s, the whole unit under it, and the run says so, as it says
    a start the camera's own range moved; it had said nothing, the user left to think the
    metering began at exposure_s."""
    cfg = _uvc_dome_config(tmp_path, max_on_s=1.5)
    cfg.write_text(cfg.read_text().replace("exposure_s = 0.05\n", "exposure_s = 0.00125\n", 1))
    light = LightHistory(SystemClock())  # type: ignore[arg-type]
    light.set(1.0)
    stream = BufferedUvcStream(light, fps=20.0, scale=1e6)
    code, said, out, _ = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code == 0, said
    assert (
        "[camera] exposure_s = 0.00125 s is not an exposure the camera uvc-camera takes "
        "exactly (it takes whole units of exposure_unit_s = 0.0001 s in [camera.device]): the "
        "metering started at 0.0012 s instead"
    ) in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    shots = manifest["schedule"]["provenance"]["exposure"]["test_exposures_by_light_s"]
    assert shots[0][0] == pytest.approx(0.0012), shots  # where the note says it started


@pytest.mark.pty
def test_no_whole_unit_inside_both_ranges_is_refused_naming_both_keys(tmp_path, monkeypatch):
    """`[camera] min_exposure_s = 0.00125` and `[camera.device] max_exposure_s = 0.00129`
    share no exposure the camera takes (its units are 0.0001 s). `check --auto-exposure` had
    passed such a pair, judging 0.0012 s (the camera's range alone), and the run started its
    metering at 0.00125 s. Both now refuse it naming both keys, the run before any LED
    lights. (Ranges that do not even meet, 0.00125 over 0.0012, are refused when the config
    loads: tests/cli/test_config_camera_exposure_ranges.py.)"""
    cfg = _min_exposure_at_start(tmp_path, "max_exposure_s = 0.00129\n")
    stream = BufferedUvcStream(LightHistory(SystemClock()), fps=20.0)  # type: ignore[arg-type]
    with monkeypatch.context() as m:
        m.setattr(cv2, "VideoCapture", lambda device, api: stream)
        with shipped_dome_on_pty(m, cfg):
            r = CliRunner().invoke(app, ["check", str(cfg), "--auto-exposure"])
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "RESULT: FAIL" in said, said
    keys = ("[camera] min_exposure_s = 0.00125 s", "max_exposure_s = 0.00129 s in [camera.device]")
    assert all(k in said for k in keys) and "Traceback" not in said, said
    code, said, out, history = _metered_run(tmp_path, monkeypatch, cfg, stream)
    assert code != 0 and all(k in said for k in keys), said
    assert not [e for e in history if e.what == "lit"], said
    assert "Traceback" not in said and not list(out.glob("*.jpg")), said
