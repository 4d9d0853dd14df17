"""``rti-rig check`` reads one frame of a UVC (OpenCV) camera and checks it as a capture
would, through the CLI on the shipped hardware example (its dome firmware emulated on a pty,
the camera OpenCV's image-sequence backend, the guide's stand-in for a UVC camera).

Before: no frame was read, so a config whose 8-bit frames had no ``response`` passed the
check and was refused at the session's first capture, the dome lit.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _config(tmp_path: Path, response: str | None) -> Path:
    """The shipped DSLR example with an 8-bit image-sequence camera in place of its DSLR."""
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(3):
        cv2.imwrite(str(frames / f"f_{i:03d}.png"), np.full((32, 48, 3), 90 + i, np.uint8))
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (CONFIGS / "example_dome_48.toml").read_text()
    head, _, rest = text.partition("[camera.device]")
    rest = rest[rest.index("\n[timing]") :]
    device = (
        f'[camera.device]\nkind = "opencv"\nbackend = "images"\ndevice = "{frames}/f_%03d.png"\n'
    )
    if response is not None:
        device += f'response = "{response}"\n'
    text = head + device + rest
    text = text.replace("width = 6000", "width = 48").replace("height = 4000", "height = 32")
    cfg = tmp_path / "uvc.toml"
    cfg.write_text(text)
    return cfg


@pytest.mark.parametrize("response", [None, "srgb"])
def test_check_reads_a_test_frame_of_a_uvc_camera(tmp_path, monkeypatch, response) -> None:
    cfg = _config(tmp_path, response)
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    if response is None:  # what the first capture would refuse, refused by the check
        assert r.exit_code == 1, said
        assert "FAILED its test shot" in said and 'set response = "srgb"' in said, said
        assert "RESULT: FAIL" in said
    else:
        assert r.exit_code == 0, said
        assert "one test frame read: 48×32, 8-bit" in said, said
