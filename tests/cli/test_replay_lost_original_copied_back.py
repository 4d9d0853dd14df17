"""A replay session's lost original is copied back from the acquisition, not reshot.

A replayed session keeps each recorded file under ``raw/`` as the step's original. One deleted
since was said as "the camera's original capture is lost … reshoot exactly those, with the
object where it was": the acquisition holds the file, so the advice is now the ``cp`` that puts
it back (its path journaled as ``copied_from``). Two files of one name in two subfolders of the
``.lp`` had been recorded under one original name (their file name): the name recorded is now
the path relative to the ``.lp``. The fit's QA verdict and export-lp, which said of it "the
camera's original capture is lost" beside that ``cp``, say what is true: the copy in ``raw/``
is missing, the acquisition still holds it; the verdict calls the session "recoverable", not
"flawed" (the recording is not at fault, the ``cp`` makes the session whole)."""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import cv2
import numpy as np
from typer.testing import CliRunner

from rti_rig.cli import app
from tests.conftest import journal, manifest, said

runner = CliRunner()
#: two files named alike in two subfolders, and six beside the .lp
#: (named with a space, as Windows exports name them: the cp must quote it)
NAMES = ("a/IMG 0001.JPG", "b/IMG 0001.JPG", *(f"IMG_{i}.JPG" for i in range(3, 9)))


def _acquisition(folder: Path) -> Path:
    rng = np.random.default_rng(7)
    lines = [str(len(NAMES))]
    for i, name in enumerate(NAMES):
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        img = rng.integers(10, 240, (24, 32, 3)).astype(np.uint8)
        assert cv2.imwrite(str(folder / name), img)
        az, el = 2 * math.pi * i / len(NAMES), math.radians(30 + 10 * (i % 3))
        x, y, z = math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)
        lines.append(f"{name} {x:.6f} {y:.6f} {z:.6f}")
    (folder / "dirs.lp").write_text("\n".join(lines) + "\n")
    return folder / "dirs.lp"


def test_a_replays_lost_original_is_copied_back_from_the_acquisition(tmp_path: Path) -> None:
    lp = _acquisition(tmp_path / "acq")
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(lp), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, said(r)
    steps = {e["index"]: e for e in journal(out)}
    listed = {s["index"]: s for s in manifest(out)["steps"]}
    for i in (0, 1):  # each by its path relative to the .lp, not both as "IMG 0001.JPG"
        raw = f"raw/image_00{i + 1}.jpg"
        for entry in (steps[i], listed[i]):
            assert entry["originals"] == {raw: NAMES[i]}
            assert entry["copied_from"] == {raw: os.path.abspath(lp.parent / NAMES[i])}
    (out / "raw" / "image_002.jpg").unlink()
    r = runner.invoke(app, ["run", "--resume", str(out)])
    text = said(r)
    assert "object where it was" not in text, text
    # the verdict (a fit without its slow models) and export-lp say the copy alone is missing
    held = "kept in raw/ is missing, the acquisition still holds it as recorded"
    fit = ["fit", str(out), "--out", str(tmp_path / "fit"), "--model", "lambert"]
    exported = ["export-lp", str(out), "--out", str(tmp_path / "x.lp")]
    for args in ([*fit, "--no-ptm", "--no-hsh"], exported):
        r = runner.invoke(app, args)
        assert r.exit_code == 0, said(r)
        assert held in said(r) and "original capture" not in said(r), said(r)
        assert "copy it back from the acquisition: cp -- " in said(r), said(r)
        if args[0] == "fit":  # judged recoverable, not "flawed"; not good until the cp
            assert "QA verdict: recoverable: image_002 (" in said(r), said(r)
            assert "flawed" not in said(r) and "cannot be reshot" not in said(r), said(r)
            assert json.loads((tmp_path / "fit" / "qa.json").read_text())["good"] is False
    line = next(x for x in text.splitlines() if "copy it back from the acquisition: " in x)
    command = line.split("copy it back from the acquisition: ", 1)[1].rstrip(".")
    subprocess.run(["sh", "-c", command], check=True, timeout=60)
    assert (out / "raw" / "image_002.jpg").read_bytes() == (lp.parent / NAMES[1]).read_bytes()
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0 and "every image is as captured" in said(r), said(r)
