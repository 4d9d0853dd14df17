"""A UVC camera unplugged mid-session (a USB hub on a laptop's battery): the run stops.

What the user must see: the camera named as the device lost, the images captured so far kept
and listed in lights.lp, the lights' state as established (the dome is still there, so its
all-off is acknowledged), a non-zero exit and how to resume; and the resume, the camera back,
finishes the session. Through ``rti-rig run`` on the shipped hardware dome (its board emulated
on a pty) with a UVC camera as OpenCV's V4L2 backend gives it (tests/fake_uvc.py): once the
device is gone, ``grab`` and ``read`` fail (VIDIOC_DQBUF answers ENODEV, and cap_v4l.cpp
returns false), as they do for every later call.
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from fake_uvc import BufferedUvcStream, LightHistory
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import SystemClock
from rti_rig.drivers.cameras import opencv_camera

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

LIGHTS = 4


class UnpluggedUvcStream(BufferedUvcStream):
    """The stream until its ``gone_after``-th frame was handed out; then the device is gone."""

    def __init__(self, gone_after: int | None) -> None:
        super().__init__(LightHistory(SystemClock()), fps=20.0, buffers=4)  # type: ignore[arg-type]
        self.gone_after = gone_after

    def _gone(self) -> bool:
        return self.gone_after is not None and len(self.delivered) >= self.gone_after

    def grab(self) -> bool:
        return False if self._gone() else super().grab()

    def read(self):  # type: ignore[no-untyped-def]
        return (False, None) if self._gone() else super().read()


def _config(tmp_path: Path) -> Path:
    """The shipped 48-LED dome with a UVC camera (4 x 8 px, 0.05 s)."""
    text = (CONFIGS / "example_dome_48.toml").read_text()
    text = text.replace('"example_dome_48.lp"', f'"{CONFIGS / "example_dome_48.lp"}"')
    text = text.replace("exposure_s = 0.125", "exposure_s = 0.05")
    text = text.replace("width = 6000\nheight = 4000", "width = 4\nheight = 8")
    text = text[: text.index("[camera.device]")] + (
        '[camera.device]\nkind = "opencv"\ndevice = 0\n\n[timing]\nlight_switch_s = 0.02\n'
        "settle_s = 0.1\nreadout_s = 0.05\ntransfer_s = 0.05\n"
    )
    cfg = tmp_path / "uvc_dome.toml"
    cfg.write_text(text)
    return cfg


def _run(monkeypatch, cfg: Path, stream, args: list[str]):  # type: ignore[no-untyped-def]
    monkeypatch.setattr(cv2, "VideoCapture", lambda device, api: stream)
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, [*args, "--no-verdict"], terminal_width=400)
        lit_at_end = firmware.lit_indices()
    return r.exit_code, " ".join(r.output.split()), lit_at_end


def _images(out: Path) -> list[str]:
    lines = (out / "lights.lp").read_text(encoding="utf-8").splitlines()[1:]
    return [line.split()[0] for line in lines if line.strip()]


def test_a_uvc_camera_unplugged_mid_session_stops_keeps_and_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = _config(tmp_path)
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)]
    # the world: /dev/video0 went with the camera (not this machine's own /dev, if it has one)
    monkeypatch.setattr(opencv_camera, "_device_node_present", lambda where: False)
    code, said, lit = _run(monkeypatch, cfg, UnpluggedUvcStream(gone_after=2), args)
    assert code == 2, said
    assert "error: uvc-camera during 'drain'" in said, said
    assert "the camera on /dev/video0 stopped delivering frames after " in said, said
    assert "/dev/video0 is gone: it was unplugged or dropped off the USB bus" in said, said
    # the dome is still there: its all-off was acknowledged, and nothing is lit
    assert "All-off sent and acknowledged by the dome: lights are off." in said, said
    assert lit == []
    assert f"2 image(s) kept in {out}, listed in lights.lp" in said, said
    assert f"Continue with: rti-rig run --resume {out}" in said, said
    kept = _images(out)
    assert len(kept) == 2 and all((out / k).is_file() for k in kept), kept
    assert "Traceback" not in said

    # the camera is back: the resume shoots the two lights left
    code, said, lit = _run(
        monkeypatch, cfg, UnpluggedUvcStream(gone_after=None), ["run", "--resume", str(out)]
    )
    assert code == 0, said
    images = _images(out)
    assert len(images) == LIGHTS and images[:2] == kept, images
    assert lit == []


def test_a_uvc_camera_that_stops_with_its_device_still_there_is_not_said_unplugged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """OpenCV's grab fails on its select() timeout too, the device node still there (a camera
    that hung): the stop says the node is there, and claims no unplugging."""
    cfg = _config(tmp_path)
    out = tmp_path / "s"
    args = ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)]
    monkeypatch.setattr(opencv_camera, "_device_node_present", lambda where: True)
    code, said, _ = _run(monkeypatch, cfg, UnpluggedUvcStream(gone_after=2), args)
    assert code == 2, said
    assert "/dev/video0 is still there, so the camera hung or its USB link reset" in said, said
    assert "unplugged or dropped off" not in said, said
    assert f"Continue with: rti-rig run --resume {out}" in said, said
