"""OpenCV's native warnings stay off the terminal of a command; rti-rig's own message stays.

A UVC camera that did not open printed ``[ WARN:0@0.204] global cap_v4l.cpp:914 open
VIDEOIO(V4L2:/dev/video0): can't open camera by index`` (twice) before rti-rig's line naming
the device and what to check (QA, 2026-12-05).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS

pytestmark = [pytest.mark.e2e]

#: A V4L2 index no test machine has a camera at.
ABSENT = 63


def _env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k != "OPENCV_LOG_LEVEL"}


def _uvc_config(tmp_path: Path) -> Path:
    text = (CONFIGS / "example_dome_48.toml").read_text()
    text = text.replace('lp_file = "', f'lp_file = "{CONFIGS}/')
    head, _, _ = text.partition("[camera.device]")
    cfg = tmp_path / "uvc.toml"
    cfg.write_text(
        head + f'[camera.device]\nkind = "opencv"\ndevice = {ABSENT}\nfourcc = "Y16 "\n'
        "exposure_unit_s = 0.0001\ngain = 0\n"
    )
    return cfg


def test_check_of_an_absent_uvc_camera_says_rti_rigs_words_only(tmp_path: Path) -> None:
    # what OpenCV prints on its own, so that this test sees the lines it keeps off
    bare = subprocess.run(
        [sys.executable, "-c", f"import cv2; cv2.VideoCapture({ABSENT}, cv2.CAP_V4L2)"],
        capture_output=True,
        text=True,
        env=_env(),
        timeout=120,
    )
    assert "WARN" in bare.stderr and "cap_v4l" in bare.stderr, bare.stderr
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", "check", str(_uvc_config(tmp_path))],
        capture_output=True,
        text=True,
        env=_env(),
        timeout=300,
    )
    assert "Traceback" not in r.stderr, r.stderr
    said = r.stdout + r.stderr
    assert f"cannot open /dev/video{ABSENT}" in said, said
    assert "WARN" not in said and "cap_v4l" not in said, said
