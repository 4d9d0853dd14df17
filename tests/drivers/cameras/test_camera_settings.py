"""Settings validation, the driver factory and master darks."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from rti_rig.core.devices import Camera
from rti_rig.drivers.cameras.dark_frames import capture_master_dark
from rti_rig.drivers.cameras.factory import build_camera
from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
from rti_rig.drivers.cameras.gphoto2_camera import Gphoto2Camera
from rti_rig.drivers.cameras.opencv_camera import OpenCvCamera
from rti_rig.drivers.cameras.raw_decode import subtract_dark
from rti_rig.drivers.cameras.raw_roundtrip import RawRoundTripCamera
from rti_rig.drivers.cameras.settings import (
    ExposureRule,
    FolderWatchSettings,
    Gphoto2CameraSettings,
    OpenCvCameraSettings,
    RawDecodeSettings,
    parse_camera_settings,
)


def test_kind_selects_the_backend_and_builds_the_driver(tmp_path):
    cases = [
        ({"kind": "opencv", "device": 2}, OpenCvCameraSettings, OpenCvCamera),
        ({"kind": "gphoto2", "iso": "200"}, Gphoto2CameraSettings, Gphoto2Camera),
        (
            {"kind": "folder_watch", "folder": str(tmp_path), "patterns": ["*.NEF"]},
            FolderWatchSettings,
            FolderWatchCamera,
        ),
    ]
    for data, settings_type, driver_type in cases:
        settings = parse_camera_settings(data)
        assert type(settings) is settings_type
        cam = build_camera(settings, output_dir=tmp_path)
        assert type(cam) is driver_type and isinstance(cam, Camera)
    assert parse_camera_settings(cases[2][0]).patterns == ("*.NEF",)


@pytest.mark.parametrize(
    "data",
    [
        {"kind": "opencv", "exposure_unti_s": 1e-4},
        {"kind": "gphoto2", "decode": {"mode": "mosaic", "gamma": 2.2}},
        {"kind": "folder_watch"},  # folder is required
        {"kind": "webcam"},
        {"kind": "gphoto2", "decode": {"white_balance": "auto"}},  # nothing automatic
    ],
)
def test_invalid_camera_tables_are_rejected(data):
    with pytest.raises(ValidationError):
        parse_camera_settings(data)


def test_settings_are_frozen_and_rules_ordered():
    s = RawDecodeSettings()
    with pytest.raises(ValidationError):
        s.mode = "half"
    with pytest.raises(ValidationError, match="min_exposure_s"):
        ExposureRule(min_exposure_s=2.0, max_exposure_s=1.0)


def test_master_dark_turns_lights_off_and_averages():
    rng = np.random.default_rng(5)
    state = {"on": True}

    class Lights:
        name = "lights"

        def all_off(self):
            state["on"] = False

    def render(t):
        base = np.full((32, 32), 0.5 if state["on"] else 0.0)
        return base + 0.01 * t + rng.normal(0.0, 1e-3, base.shape)

    cam = RawRoundTripCamera("sim", render, RawDecodeSettings(), black_level=0, white_level=65535)
    cam.connect()
    dark = capture_master_dark(cam, 1.0, count=8, lights=Lights())
    assert state["on"] is False and dark.metadata["dark_count"] == 8
    assert np.mean(dark.pixels) / 65535 == pytest.approx(0.01, abs=2e-4)
    assert np.std(dark.pixels / 65535) < 1e-3 / np.sqrt(8) * 1.5  # averaging reduces noise
    state["on"] = True
    img = subtract_dark(cam.capture(1.0), dark)
    assert np.mean(img.pixels) / 65535 == pytest.approx(0.5, abs=5e-4)


@pytest.mark.parametrize("device", [-1, -3, "", "  "])
def test_a_uvc_device_that_names_no_camera_is_refused_at_load(device):
    """``device = -1`` had been taken, and failed at connect as "cannot open /dev/video-1"."""
    with pytest.raises(ValidationError, match="names no camera: give its index"):
        parse_camera_settings({"kind": "opencv", "device": device})


@pytest.mark.parametrize("device", ["-1", "0", " 2"])
def test_a_uvc_index_in_quotes_is_refused_at_load(device):
    with pytest.raises(ValidationError, match="is a number in quotes, which is read as a file"):
        parse_camera_settings({"kind": "opencv", "device": device})


@pytest.mark.parametrize("device", [0, 3, "/dev/video0", "/dev/v4l/by-id/usb-cam-video-index0"])
def test_a_uvc_device_index_or_path_is_taken(device):
    assert parse_camera_settings({"kind": "opencv", "device": device}).device == device
