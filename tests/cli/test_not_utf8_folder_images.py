"""Images in a folder whose name is not UTF-8 (an archive unpacked with its Windows names) are
read and written: OpenCV, given such a path as a str (its lone surrogate), crashes the process
with a segmentation fault, so every path handed to it is given as the bytes on disk.

Run in a child process: the crash, if it came back, would otherwise end the test run.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from conftest import NOT_UTF8_NAME, rti_rig_in_ascii_locale


@pytest.fixture
def odd(tmp_path: Path) -> Path:
    """A folder whose name is not UTF-8."""
    folder = tmp_path / os.fsdecode(NOT_UTF8_NAME)
    folder.mkdir()
    return folder


def test_an_acquisition_in_a_folder_whose_name_is_not_utf8_fits(odd: Path) -> None:
    """OpenCV, given such a path as a str (its lone surrogate), crashed the process with a
    segmentation fault reading the first image (and writing normals.png): an archive unpacked
    with its Windows names, fitted, ended with no word and exit -11."""
    import cv2

    lines = ["6"]
    for i in range(6):
        az, el = 2 * np.pi * i / 6, np.radians(30 + 30 * (i % 2))
        d = (np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el))
        grey = np.full((24, 32), 40 + 30 * i, np.uint8)
        (odd / f"img{i}.jpg").write_bytes(cv2.imencode(".jpg", grey)[1].tobytes())
        lines.append(f"img{i}.jpg " + " ".join(f"{c:.6f}" for c in d))
    (odd / "dirs.lp").write_text("\n".join(lines) + "\n")
    r = rti_rig_in_ascii_locale(
        "fit", odd / "dirs.lp", "--out", odd / "fit", "--model", "ps", "--no-qa"
    )
    assert r.returncode == 0, (r.returncode, r.stderr)
    assert (odd / "fit" / "normals.png").is_file()
