"""Images in a folder whose name is not UTF-8 (an archive unpacked with its Windows names) are
read and written: OpenCV, given such a path as a str (its lone surrogate), crashes the process
with a segmentation fault, so every path handed to it is given as the bytes on disk.

Run in a child process: the crash, if it came back, would otherwise end the test run.
"""

from __future__ import annotations

from pathlib import Path

from conftest import rti_rig_in_ascii_locale


def test_an_acquisition_in_a_folder_whose_name_is_not_utf8_fits(
    not_utf8_acquisition: Path,
) -> None:
    """OpenCV, given such a path as a str (its lone surrogate), crashed the process with a
    segmentation fault reading the first image (and writing normals.png): an archive unpacked
    with its Windows names, fitted, ended with no word and exit -11."""
    odd = not_utf8_acquisition.parent
    r = rti_rig_in_ascii_locale(
        "fit", not_utf8_acquisition, "--out", odd / "fit", "--model", "ps", "--no-qa"
    )
    assert r.returncode == 0, (r.returncode, r.stderr)
    assert (odd / "fit" / "normals.png").is_file()
