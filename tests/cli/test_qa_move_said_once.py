"""A move part-way through is said once in the verdict, however many of its images have
another problem too.

Found on the virtual arm's tablet (12 lights) moved (2, 0) px from image 7, image 10 also
clipped: the verdict read "image_007 ... image_009 (3 images: object or camera moved from
image_007 on: …; reshoot the whole session …), image_010 (saturated: …; object or camera moved
from image_007 on: …; reshoot the whole session …), image_011 (object or camera moved …),
image_012 (object or camera moved …)": the move's long advice four times, because the run of
moved images was cut around the one with a second problem (and a run shorter than three was
spelt out image by image). A 48-light session moved from image 25 with six clipped images in
the run said it eight times. Now the move is one range, and the other problems are said on
their own.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff, write_linear_tiff

runner = CliRunner()


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _changed_copy(session: Path, dst: Path, first: int, dx: int, clipped: int) -> Path:
    """``session`` with its linear images from ``first`` (1-based) on shifted ``dx`` px to the
    right (the object nudged once) and image ``clipped`` four times as bright (part of it
    clipped), their checksums in the journal and manifest as the capture would have written
    them."""
    shutil.copytree(session, dst)
    files = sorted((dst / "linear").glob("image_*.tif"))
    renamed = {}
    for k, f in enumerate(files, start=1):
        if k < first and k != clipped:
            continue
        before = _sha(f)
        img = read_linear_tiff(f)
        if k >= first:
            img = np.roll(img, dx, axis=1)
        if k == clipped:
            img = np.clip(img.astype(np.float64) * 4.0, 0, 65535).astype(np.uint16)
        f.unlink()
        write_linear_tiff(f, img)
        renamed[before] = _sha(f)
    for name in ("journal.jsonl", "manifest.json"):
        text = (dst / name).read_text()
        for old, new in renamed.items():
            text = text.replace(old, new)
        (dst / name).write_text(text)
    return dst


def test_the_move_is_said_once_beside_an_image_with_another_problem(
    arm_tablet_12: Path, tmp_path: Path
) -> None:
    moved = _changed_copy(arm_tablet_12, tmp_path / "moved", first=7, dx=2, clipped=10)
    out = tmp_path / "f"
    r = runner.invoke(app, ["fit", str(moved), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    verdict = qa["verdict"]
    assert qa["reshoot"] == [f"image_{i:03d}" for i in range(7, 13)], verdict
    assert verdict.count("moved from image_007 on") == 1, verdict
    assert verdict.count("reshoot the whole session") == 1, verdict
    assert "image_007 ... image_012 (6 images: object or camera moved from image_007 on" in verdict
    assert "image_010 (saturated:" in verdict, verdict
    # the per-image record keeps both problems of the clipped, moved image
    problems = next(c for c in qa["images"] if c["name"] == "image_010")["problems"]
    assert any(p.startswith("saturated") for p in problems), problems
    assert any(p.startswith("object or camera moved from image_007") for p in problems), problems
    # and what the user reads says the same
    said = " ".join(r.output.split())
    assert said.count("reshoot the whole session") == 1, said
