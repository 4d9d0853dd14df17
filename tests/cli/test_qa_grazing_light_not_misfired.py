"""A grazing light that lights little is not a misfire; a dim or dead one there still is.

The shipped arm (256 px tablet) run with the default uniform layout down to 0° elevation, every
light fired where it was recorded, had been told "reshoot: image_002 (misfired or dim light:
43% of the brightness of the images of its 4 nearest lights …), image_017 (… 3% …) …" for
every light below about 4°: there the relief's cast shadows, which the fit does not model,
cover most of what the light reaches and change steeply with elevation, so the image's median
gain against its higher neighbours' says nothing. A reshoot gives the same images. Such a light
is now judged on its brightest pixels against its neighbours' (where those agree with the
prediction), and otherwise said "grazing light: too little lit to judge".
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff, write_linear_tiff

runner = CliRunner()


def _elevations(session: Path) -> dict[str, float]:
    rows = (session / "lights.lp").read_text().split("\n")[1:]
    out = {}
    for row in filter(None, rows):
        name, *xyz = row.split()
        x, y, z = (float(v) for v in xyz)
        out[Path(name).stem] = float(np.degrees(np.arctan2(z, np.hypot(x, y))))
    return out


def _scaled(session: Path, name: str, factor: float) -> None:
    tif = session / "linear" / f"{name}.tif"
    px = read_linear_tiff(tif).astype(np.float64) * factor
    tif.unlink()
    write_linear_tiff(tif, np.clip(np.round(px), 0, 65535).astype(np.uint16))


@pytest.mark.slow  # a 40-light session of the shipped arm and one fit of a faulty copy
def test_grazing_lights_are_not_misfires_and_a_dim_or_dead_one_is_named(tmp_path: Path) -> None:
    session = tmp_path / "s"
    r = runner.invoke(
        app,
        [
            "run",
            str(CONFIGS / "simulated_arm.toml"),
            "--out",
            str(session),
            "--lights",
            "40",
            "--min-elevation-deg",
            "0",
            "--max-elevation-deg",
            "20",
        ],
    )
    assert r.exit_code == 0, r.output
    elevation = _elevations(session)
    grazing = sorted(n for n, e in elevation.items() if e < 4.0)
    assert len(grazing) >= 6, elevation  # the session has the lights at issue
    said = " ".join(r.output.split())
    assert "QA verdict: good" in said, said
    assert "misfired" not in said, said
    assert "grazing light: too little lit to judge" in said, said

    # a real fault at two of those grazing lights: one at half power, one that did not fire
    assert elevation["image_017"] < 4.0 and elevation["image_002"] < 4.0, elevation
    faulty = tmp_path / "faulty"
    shutil.copytree(session, faulty)
    for name in ("journal.jsonl", "manifest.json"):  # a fault injected, not a file changed
        (faulty / name).unlink(missing_ok=True)
    _scaled(faulty, "image_017", 0.5)
    _scaled(faulty, "image_002", 0.0)
    out = tmp_path / "fit"
    r = runner.invoke(
        app, ["fit", str(faulty), "--out", str(out), "--no-ptm", "--no-hsh", "--no-normals"]
    )
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    problems = {c["name"]: c["problems"] for c in qa["images"] if c["problems"]}
    assert set(problems) == {"image_002", "image_017"}, qa["verdict"]
    assert problems["image_002"][0].startswith("misfired, no light"), problems
    assert problems["image_017"][0].startswith("misfired or dim light"), problems
