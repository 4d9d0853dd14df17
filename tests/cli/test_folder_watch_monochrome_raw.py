"""A monochrome camera's DNG (LinearRaw, one sample: no colour filter) saved into the watched
folder of the shipped folder-watch dome, which is set to make colour images (its
``[camera.device.decode] mode = "demosaic"``): ``rti-rig run`` refuses it at once, as a grey
picture where the camera is set for colour, naming the setting and what to do instead.

LibRaw reads such a file as one colour with colour codes that mean nothing (6): it had been
refused as a colour filter array whose "CFA tags are damaged or lost", with advice to copy the
shot again from the card, which no copy can follow. The DNG comes from the tests' own writer
(written from the TIFF and DNG specifications): PhotometricInterpretation 34892 (LinearRaw),
SamplesPerPixel 1, no CFA tags.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import folder_watch_config, tethered_run
from dng_spec_writer import monochrome_dng

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def test_run_refuses_a_monochrome_cameras_dng_where_the_camera_is_set_for_colour(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    cfg = folder_watch_config(tmp_path, tether)
    assert 'mode = "demosaic"' in cfg.read_text(encoding="utf-8")  # a colour camera
    data = monochrome_dng(np.full((32, 48), 20000, np.uint16))
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, [("IMG_0001.dng", data)], out)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert f"{tether / 'IMG_0001.dng'}: " in said and ".incoming" not in said, said
    assert "it is a monochrome sensor's file" in said, said
    assert '[camera.device.decode] mode = "demosaic"' in said, said
    assert 'with a folder-watch camera (patterns = ["*.tif"] in its [camera.device])' in said
    assert "damaged" not in said and "copy the shot again" not in said.lower(), said
    assert "waiting will not help" in said and f"left in {tether}" in said, said
    assert "did not change within" not in said, said  # not waited for
    assert not list((out / "linear").glob("image_*.tif")), said
    assert (tether / "IMG_0001.dng").read_bytes() == data  # left as the program saved it
    assert lit_at_end == []  # the dome was switched off
