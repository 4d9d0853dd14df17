"""A move part-way through a session is found and named from its first moved image.

Found by an injection sweep over correct sessions: the object moved by (1, 2) px from image 25
of the shipped simulated dome's 48 was named "moved" on 10 scattered images of the 24, and a
(2, 0) px move from image 7 of 12 was called "good". With half the images at each position
every reference the checks use (the median edge image, the fit) is a blend of the two
(rti_rig.reconstruct.qa_drift.find_step). The verdict now names the move once, from its first
image on, with what to do; a session that held still stays good.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.image_files import read_linear_tiff, write_linear_tiff

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("dome") / "s"
    config = REPO / "rig_configs" / "simulated_dome.toml"
    r = runner.invoke(app, ["run", str(config), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    return out


def _verdict(session: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "QA verdict:" in text, text
    return json.loads((out / "qa.json").read_text())


def _moved_copy(session: Path, dst: Path, first: int, dx: int, dy: int) -> Path:
    """A copy of ``session`` whose images from ``first`` (1-based) on are shifted by
    ``(dx, dy)`` px (x right, y down): the object nudged once, part-way through."""
    import shutil

    shutil.copytree(session, dst)
    files = sorted((dst / "linear").glob("image_*.tif"))
    for f in files[first - 1 :]:
        img = read_linear_tiff(f)
        f.unlink()
        write_linear_tiff(f, np.roll(img, (dy, dx), axis=(0, 1)))
    return dst


def test_a_move_from_image_25_of_48_is_named_from_there_on(session: Path, tmp_path: Path) -> None:
    moved = _moved_copy(session, tmp_path / "moved", 25, 1, 2)
    qa = _verdict(moved, tmp_path / "f")
    assert qa["reshoot"][:1] == ["image_025"], qa["verdict"]
    assert set(qa["reshoot"]) >= {f"image_{i:03d}" for i in range(25, 49)}, qa["verdict"]
    assert "moved from image_025 on" in qa["verdict"], qa["verdict"]
    assert "reshoot from image_025 on" in qa["verdict"], qa["verdict"]
    first = next(c for c in qa["images"] if c["name"] == "image_025")
    np.testing.assert_allclose(first["drift_px"], [1.0, -2.0], atol=0.5)  # x right, y up


def test_the_same_session_held_still_is_good(session: Path, tmp_path: Path) -> None:
    qa = _verdict(session, tmp_path / "f")
    assert qa["good"], qa["verdict"]
