"""On a glossy object a shift against the fit alone is claimed only where the image's edges
show it too, also where the edges are trusted.

The shipped simulated dome at 1024 px with its scene set to the coin, 12 lights, image_011
moved (2, 1) px: with the fit made of every other image (none of them called dim), image_009,
a 55° light whose highlight the Lambertian fit cannot render, was told "object or camera
moved: shifted (-119.7, -0.8) px against the others" beside the real image_011. Its own edges
had not moved. Where the edges are not trusted such a shift was already refused; now it is
where they are trusted too.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff, write_linear_tiff

runner = CliRunner()


@pytest.mark.slow  # a 12-light session of the coin at 1024 px, then a fit of a copy of it
def test_only_the_moved_image_is_called_moved_on_the_coin(
    tmp_path: Path, dome_coin_1024_12: Path
) -> None:
    moved = tmp_path / "moved"
    shutil.copytree(dome_coin_1024_12, moved)
    for name in ("journal.jsonl", "manifest.json"):  # a fault injected, not a file changed
        (moved / name).unlink(missing_ok=True)
    tif = moved / "linear" / "image_011.tif"
    px = np.roll(read_linear_tiff(tif), (1, 2), axis=(0, 1))  # 2 px right, 1 px down
    tif.unlink()
    write_linear_tiff(tif, px)
    out = tmp_path / "fit"
    r = runner.invoke(
        app, ["fit", str(moved), "--out", str(out), "--no-ptm", "--no-hsh", "--no-normals"]
    )
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    called_moved = {
        c["name"]
        for c in qa["images"]
        if any(p.startswith("object or camera") for p in c["problems"])
    }
    assert called_moved == {"image_011"}, qa["verdict"]
