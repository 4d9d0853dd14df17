"""The benchmarks' images are written and read in a folder whose name is not UTF-8 (a TMPDIR, or
a data folder, under a Latin-1 name): OpenCV, given such a path as a str (its lone surrogate),
crashes the process with a segmentation fault, so the benchmarks hand it the bytes on disk, as
rti_rig does (``os.fsencode``).

Run in a child process: the crash, if it came back, would otherwise end the test run.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from conftest import NOT_UTF8_NAME, REPO

CHILD = """
import sys
from pathlib import Path
from benchmarks import fit_session, planner_real_data, planning_time

odd = Path(sys.argv[1])  # the folder's bytes, as Python holds them: a lone surrogate
jpeg = fit_session.make_jpeg_session(odd / "big", 16, 12, 4)   # cv2.imwrite
(jpeg / "lights.lp").rename(jpeg / "dirs.lp")
_, lum, rgb8 = planner_real_data.load(jpeg)                     # cv2.imread
assert lum.shape == (4, 12, 16) and rgb8[0].shape == (12, 16, 3), lum.shape
session = fit_session.make_session(odd / "s", 16, 12, 4)
fit_session.make_twins(session, odd / "jpeg", odd / "zlib")      # cv2.imwrite
assert len(list((odd / "jpeg").glob("*.jpg"))) == 4
preview, _ = planning_time.cli_inputs(odd)                      # cv2.imwrite
assert preview.is_file()
print("ok")
"""


def test_the_benchmarks_images_are_written_and_read_in_a_folder_not_utf8(tmp_path: Path) -> None:
    odd = tmp_path / os.fsdecode(NOT_UTF8_NAME)
    odd.mkdir()
    r = subprocess.run(
        [sys.executable, "-c", CHILD, os.fsencode(odd)],
        capture_output=True,
        text=True,
        cwd=REPO,
        env={**os.environ, "PYTHONPATH": str(REPO)},
        timeout=600,
    )
    assert r.returncode == 0, (r.returncode, r.stderr[-2000:])
    assert r.stdout.strip() == "ok", r.stdout
