"""An acquisition black throughout is not "good".

Every image black (a lens cap left on, lights that never fired) had been called "QA verdict:
good", with only "brightness not judged … (too few pixels lit)": each image's brightness is
judged against what the other images predict, and black against black predicts black.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp, write_lp

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"


def test_a_black_acquisition_is_called_so(tmp_path: Path) -> None:
    entries = read_lp(ACQ)
    for e in entries:
        cv2.imwrite(str(tmp_path / e.name), np.zeros((64, 64, 3), np.uint8))
    lp = tmp_path / "dirs.lp"
    write_lp(lp, entries)
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-ptm"])
    said = " ".join(r.output.split())
    assert "QA verdict: good" not in said, said
    # said once, with the count and the likely causes (it had come once per image)
    assert said.count("no light in any image") == 1, said
    assert f"({len(entries)} images: next to no light in any image" in said, said
    assert "(a lens cap left on, lights that never fired, or an exposure far too short)" in said
    assert "misfired" not in said, said


def test_a_small_object_on_black_velvet_is_not_called_black_throughout(tmp_path: Path) -> None:
    """An object under 1 % of the frame (a 5 x 5 patch of 64 x 64) on a black ground: each
    image's "brightest pixels" had been its 99th percentile, black, so every image was called
    "misfired, no light … as every image's do" (now "no light in any image"). Its brightest
    0.1 % are the object's."""
    entries = read_lp(ACQ)
    for e in entries:
        img = np.zeros((64, 64, 3), np.uint8)
        photo = cv2.resize(cv2.imread(str(ACQ.parent / e.name)), (64, 64))
        img[30:35, 30:35] = np.maximum(photo[30:35, 30:35], 20)  # lit, if dimly
        cv2.imwrite(str(tmp_path / e.name), img)
    lp = tmp_path / "dirs.lp"
    write_lp(lp, entries)
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-ptm"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "QA verdict" in said, said
    assert "no light in any image" not in said, said
    assert said.count("misfired, no light") == 0, said


def test_a_very_dark_acquisition_is_not_said_to_have_no_light(tmp_path: Path) -> None:
    """The real replay at a far too short exposure (its frames scaled to 0-5 DN): below the
    black level of every image, so reshot, but each still a picture of the object under its
    light; the verdict had said "no light in any image" of it."""
    entries = read_lp(ACQ)
    for e in entries:
        img = cv2.imread(str(ACQ.parent / e.name)).astype(np.float32)
        cv2.imwrite(str(tmp_path / e.name), np.round(img * (5.0 / img.max())).astype(np.uint8))
    lp = tmp_path / "dirs.lp"
    write_lp(lp, entries)
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--no-ptm"])
    said = " ".join(r.output.split())
    assert "QA verdict: good" not in said, said
    assert said.count("next to no light in any image") == 1, said
    assert ": no light in any image" not in said, said
