"""Camera kinds are a registry: the built-ins, a clear error for an unknown kind, and the worked
example of docs/extending.md plugged in as written."""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

import pytest
from pydantic import ValidationError

from rti_rig.drivers.cameras import kinds
from rti_rig.drivers.cameras.factory import build_camera
from rti_rig.drivers.cameras.settings import parse_camera_settings

REPO = Path(__file__).resolve().parents[3]
DOC = REPO / "docs" / "extending.md"


def doc_example() -> str:
    block = re.search(
        r"```python\n(# my_cameras/test_pattern.py\n.*?)```", DOC.read_text(encoding="utf-8"), re.S
    )
    assert block, "docs/extending.md lost its camera example"
    return block.group(1)


@pytest.fixture
def test_pattern(tmp_path, monkeypatch):
    package = tmp_path / "my_cameras"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "test_pattern.py").write_text(doc_example(), encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    module = importlib.import_module("my_cameras.test_pattern")
    yield module
    kinds._KINDS.pop("test_pattern", None)
    for name in ("my_cameras.test_pattern", "my_cameras"):
        sys.modules.pop(name, None)


def test_the_built_in_kinds_are_registered():
    assert kinds.camera_kind_names()[:3] == ("opencv", "gphoto2", "folder_watch")


def test_a_kind_says_its_exposure_end_exactly_when_its_driver_does():
    """The config's max_on_s check counts the transfer for a camera that holds its LED lit
    until its frame is in; the controller switches the LED off early only for an
    ExposingCamera. The two answers must agree for every built-in kind."""
    from rti_rig.core.devices import ExposingCamera
    from rti_rig.drivers.cameras.folder_watch import FolderWatchCamera
    from rti_rig.drivers.cameras.gphoto2_camera import Gphoto2Camera
    from rti_rig.drivers.cameras.opencv_camera import OpenCvCamera

    drivers = {"opencv": OpenCvCamera, "gphoto2": Gphoto2Camera, "folder_watch": FolderWatchCamera}
    for name, driver in drivers.items():
        kind = kinds.camera_kind(name)
        assert kind is not None and kind.says_exposure_end == issubclass(driver, ExposingCamera)


def test_an_unknown_kind_names_the_key_and_the_known_kinds():
    with pytest.raises(ValidationError) as info:
        parse_camera_settings({"kind": "webcam"})
    error = info.value.errors()[0]
    assert error["loc"] == ("kind",)
    assert "unknown camera kind; use one of 'opencv', 'gphoto2', 'folder_watch'" in error["msg"]


def test_the_documented_kind_is_validated_built_and_captures(test_pattern):
    settings = parse_camera_settings({"kind": "test_pattern", "width": 8, "height": 4})
    assert isinstance(settings, test_pattern.TestPatternSettings)
    camera = build_camera(settings)
    camera.connect()
    frame = camera.capture(0.5)
    camera.close()
    assert frame.pixels.shape == (4, 8) and int(frame.pixels[0, 0]) == 10000
    with pytest.raises(ValidationError):  # its own settings are validated like a built-in's
        parse_camera_settings({"kind": "test_pattern", "width": 0})


def test_a_kind_is_registered_once(test_pattern):
    kind = kinds.camera_kind("test_pattern")
    with pytest.raises(ValueError, match="already registered"):
        kinds.register_camera_kind(kinds.CameraKind(kind.name, kind.settings, kind.build))
