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


@pytest.mark.parametrize("imported_first", [False, True])
def test_opencvs_level_is_set_to_errors_unless_the_user_set_one(imported_first: bool) -> None:
    """In a fresh process: OpenCV's log level ERROR after the command line's set-up, whether
    OpenCV was imported before it or after; a level the user set is left as set."""
    code = (
        ("import cv2; " if imported_first else "")
        + "import os; from rti_rig.cli.app import opencv_warnings_quiet; "
        "opencv_warnings_quiet(); import cv2; "
        "print(os.environ['OPENCV_LOG_LEVEL'], cv2.utils.logging.getLogLevel() == "
        "cv2.utils.logging.LOG_LEVEL_ERROR)"
    )
    run = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=_env(), timeout=120
    )
    assert run.stdout.split() == ["ERROR", "True"], run.stdout + run.stderr
    mine = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={**_env(), "OPENCV_LOG_LEVEL": "DEBUG"},
        timeout=120,
    )
    assert mine.stdout.split()[0] == "DEBUG", mine.stdout + mine.stderr


def test_check_of_an_absent_uvc_camera_says_rti_rigs_words_only(tmp_path: Path) -> None:
    # what OpenCV prints on its own, so that this test sees the lines it keeps off: a build
    # without V4L2, or that warns in other words, has nothing here to keep off (the test
    # above checks the level on any build)
    bare = subprocess.run(
        [sys.executable, "-c", f"import cv2; cv2.VideoCapture({ABSENT}, cv2.CAP_V4L2)"],
        capture_output=True,
        text=True,
        env=_env(),
        timeout=120,
    )
    if "WARN" not in bare.stderr:
        pytest.skip(f"this OpenCV build prints no warning for /dev/video{ABSENT}: {bare.stderr!r}")
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
