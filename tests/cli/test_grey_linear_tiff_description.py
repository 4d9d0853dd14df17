"""A grey (one-channel) image not from a RAW is said to be linear grey in its linear TIFF.

Why: 4ca842a4 labelled every linear TIFF not from a RAW "linear sRGB …": a grey replayed
acquisition's TIFFs were called sRGB, colours they have none of. Through the front door: a
replayed acquisition of grey PNGs, run, and its TIFFs read back with tifffile; the manifest's
``image_colour`` says the same of them."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import tifffile
from conftest import manifest
from typer.testing import CliRunner

from rti_rig.cli import app


def test_a_grey_replayed_image_is_said_to_be_linear_grey(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    acq.mkdir()
    rng = np.random.default_rng(3)
    lines = ["6"]
    for i in range(6):
        az, el = 2 * math.pi * i / 6, math.radians(40)
        name = f"img{i:02d}.png"
        cv2.imwrite(str(acq / name), rng.integers(40, 200, (24, 32), dtype=np.uint8))
        d = (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
        lines.append(f"{name} {d[0]:.6f} {d[1]:.6f} {d[2]:.6f}")
    (acq / "dirs.lp").write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = tmp_path / "s"
    r = CliRunner(env={"COLUMNS": "400"}).invoke(
        app, ["run", str(acq / "dirs.lp"), "--out", str(out), "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    tiffs = sorted((out / "linear").glob("*.tif"))
    assert len(tiffs) == 6
    for tif in tiffs:
        with tifffile.TiffFile(tif) as f:
            page = f.pages[0]
            assert page.ndim == 2, page.shape
            assert page.description.startswith("rti-rig: linear grey"), page.description
            assert "sRGB (" not in page.description and "NOT sRGB-encoded" in page.description
    # the manifest agrees with the files (it had called them linear sRGB, ICC-tagged), in one
    # sentence (it had two parentheticals back to back)
    linear = manifest(out)["image_colour"]["linear"]
    assert linear.startswith("linear grey") and "sRGB (" not in linear, linear
    assert "ImageDescription" in linear and ") (" not in linear, linear
