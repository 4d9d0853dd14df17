"""One flat frame among lit images is named by the QA.

A frame of one grey level (a frame from another source, a covered lens, a camera that sent a
blank buffer) among images of the object was judged "good" at a level near its mates' (the
simulated tablet, the real replay's image29 at its own median), and "too bright for its light"
above it: the per-image checks compare it with a fit it matches on average.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
from conftest import qa_of

from rti_rig.core.lp_format import read_lp, write_lp

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
FLAT = "a flat frame: no picture of the object"


def _replay(folder: Path, flat: str | None) -> Path:
    """The real replay acquisition, ``flat`` (an image name) made one grey level: its median."""
    folder.mkdir()
    entries = read_lp(ACQ)
    for e in entries:
        img = cv2.imread(str(ACQ.parent / e.name))
        if e.name == flat:
            img = np.full_like(img, int(np.median(img)))
        cv2.imwrite(str(folder / e.name), img)
    write_lp(folder / "dirs.lp", entries)
    return folder / "dirs.lp"


def test_a_flat_frame_in_a_real_acquisition_is_named(tmp_path: Path) -> None:
    said, qa = qa_of(_replay(tmp_path / "acq", "image29.jpg"), tmp_path / "f")
    assert f"image29 ({FLAT} (one level across the frame" in said, said
    assert "reshoot it" in said
    named = [c["name"] for c in qa["images"] if any(FLAT in p for p in c["problems"])]
    assert named == ["image29"], named


def test_the_real_acquisition_itself_has_no_flat_frame(tmp_path: Path) -> None:
    said, _ = qa_of(_replay(tmp_path / "acq", None), tmp_path / "f")
    assert "QA verdict" in said
    assert "flat frame" not in said, said


def test_a_flat_frame_at_its_mates_level_in_a_simulated_session(
    tmp_path: Path, arm_tablet_12: Path
) -> None:
    """At the level of the images lit from its elevation the frame had read "good"."""
    acq = tmp_path / "acq"
    acq.mkdir()
    for f in [*arm_tablet_12.glob("image_*.jpg"), arm_tablet_12 / "lights.lp"]:
        shutil.copy(f, acq / f.name)
    correct, _ = qa_of(acq, tmp_path / "f0")
    assert "QA verdict: good" in correct and "flat frame" not in correct, correct
    img = cv2.imread(str(acq / "image_005.jpg"))
    cv2.imwrite(str(acq / "image_005.jpg"), np.full_like(img, int(img.mean())))
    said, _ = qa_of(acq, tmp_path / "f")
    assert f"image_005 ({FLAT}" in said, said
    assert "QA verdict: good" not in said
