"""On a glossy object whose edges are trusted, one image's edges alone show a move only beyond
their noise: its highlights' edges move with the light.

Found on the shipped simulated dome's coin at 1024 px and 12 lights, which held still: its
edges were trusted (a median spread of 0.28 px over the 8 images measured), yet two of those
images read 0.82 and 1.05 px off, and the verdict said "reshoot: ... image_011 (object or camera
moved: shifted (-1.0, -0.1) px against the others)". Image 11 really moved by (2, 1) px is
still named, and the verdict says which shift it cannot judge.
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


@pytest.fixture(scope="module")
def coin(dome_coin_1024_12: Path) -> Path:
    return dome_coin_1024_12


def _qa(session: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(
        app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh", "--no-normals"]
    )
    assert r.exit_code == 0, r.output
    return json.loads((out / "qa.json").read_text())


@pytest.mark.slow
def test_a_still_glossy_coin_has_no_image_called_moved(coin: Path, tmp_path: Path) -> None:
    qa = _qa(coin, tmp_path / "fit")
    moved = [c["name"] for c in qa["images"] if any("moved" in p for p in c["problems"])]
    assert moved == [], qa["verdict"]
    assert "px or less not judged" in qa["verdict"], qa["verdict"]


@pytest.mark.slow
def test_one_image_of_the_glossy_coin_moved_is_named(coin: Path, tmp_path: Path) -> None:
    session = tmp_path / "moved"
    shutil.copytree(coin, session)
    for x in ("journal.jsonl", "manifest.json"):  # a folder of images and its .lp
        (session / x).unlink()
    f = session / "linear" / "image_011.tif"
    img = read_linear_tiff(f)
    f.unlink()
    write_linear_tiff(f, np.roll(img, (1, 2), axis=(0, 1)))  # (2, 1) px: x right, y down
    qa = _qa(session, tmp_path / "fit")
    c = next(c for c in qa["images"] if c["name"] == "image_011")
    assert any(p.startswith("object or camera moved") for p in c["problems"]), qa["verdict"]
