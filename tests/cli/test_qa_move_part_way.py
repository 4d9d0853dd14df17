"""A move part-way through a session is found and named from its first moved image.

Found by an injection sweep over correct sessions: the object moved by (1, 2) px from image 25
of the shipped simulated dome's 48 was named "moved" on 10 scattered images of the 24, and a
(2, 0) px move from image 7 of 12 was called "good". With half the images at each position
every reference the checks use (the median edge image, the fit) is a blend of the two
(rti_rig.reconstruct.qa_drift.find_step); with most of the images moved (from image 10 of
48) the ones that held still were called moved. The verdict now names the move once, from its
first image on, with what to do; a session that held still stays good.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import moved_session_copy, said
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


@pytest.fixture(scope="module")
def session(dome_relief: Path) -> Path:
    return dome_relief  # read only: the tests move a copy


def _verdict(session: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "QA verdict:" in text, text
    return json.loads((out / "qa.json").read_text())


_moved_copy = moved_session_copy


@pytest.mark.parametrize(
    ("first", "dx", "dy"),
    [
        (25, 1, 2),  # half the session: was named on 10 scattered images of the 24
        (10, 0, 2),  # most of it: the 9 images that held still were called moved instead
    ],
)
def test_a_move_part_way_is_named_from_its_first_image_on(
    session: Path, tmp_path: Path, first: int, dx: int, dy: int
) -> None:
    moved = _moved_copy(session, tmp_path / "moved", first, dx, dy)
    qa = _verdict(moved, tmp_path / "f")
    name = f"image_{first:03d}"
    assert qa["reshoot"] == [f"image_{i:03d}" for i in range(first, 49)], qa["verdict"]
    assert f"moved from {name} on" in qa["verdict"], qa["verdict"]
    assert (
        f"reshoot the whole session (reshooting from {name} on keeps two positions"
        in (qa["verdict"])
    ), qa["verdict"]
    shift = next(c for c in qa["images"] if c["name"] == name)["drift_px"]
    np.testing.assert_allclose(shift, [dx, -dy], atol=0.5)  # x right, y up


def test_the_same_session_held_still_is_good(session: Path, tmp_path: Path) -> None:
    qa = _verdict(session, tmp_path / "f")
    assert qa["good"], qa["verdict"]


def test_the_tablet_held_still_is_not_called_moved(arm_tablet_12: Path, tmp_path: Path) -> None:
    qa = _verdict(arm_tablet_12, tmp_path / "f")
    assert "moved" not in qa["verdict"], qa["verdict"]


def test_a_move_on_the_tablet_is_named_from_its_first_image(
    arm_tablet_12: Path, tmp_path: Path
) -> None:
    """The first split (from whole-pixel peaks against the blended median) put the move at
    image_010; each image's own test against the two positions puts it at image_007."""
    moved = _moved_copy(arm_tablet_12, tmp_path / "moved", 7, 2, 0)
    qa = _verdict(moved, tmp_path / "f")
    assert "moved from image_007 on" in qa["verdict"], qa["verdict"]
    assert qa["reshoot"] == [f"image_{i:03d}" for i in range(7, 13)], qa["verdict"]
