"""A simulated arm's park pose inside the keep-out cone around the camera, or below the
object's plane, is refused before anything moves, naming the key and its line.

``virtual_arm.toml`` with ``park_elevation_deg = 89`` (its cone begins at 80°) had passed
``check`` and parked the lamp in the camera's way; the Dynamixel arm's settings refuse such a
pose. A park above a lowered ceiling but clear of the cone is no danger, and is taken.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

SHIPPED = "park_elevation_deg = 45.0"


def _virtual_arm(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    text = (CONFIGS / "virtual_arm.toml").read_text()
    for old, new in edits:
        assert old in text
        text = text.replace(old, new)
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text)
    return cfg


@pytest.mark.parametrize(("park", "where"), [("89", "inside the keep-out cone"), ("-3", "below")])
def test_an_unsafe_park_is_refused_by_key_and_line(tmp_path: Path, park: str, where: str) -> None:
    cfg = _virtual_arm(tmp_path, (SHIPPED, f"park_elevation_deg = {park}"))
    line = 1 + cfg.read_text().splitlines().index(f"park_elevation_deg = {park}")
    r = CliRunner().invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"line {line}: key 'arm.park_elevation_deg': {park} is {where}" in text, text
    assert "give a park pose from 0 to 80 degrees" in text, text


def test_a_park_above_a_lowered_ceiling_but_clear_of_the_cone_is_taken(tmp_path: Path) -> None:
    cfg = _virtual_arm(tmp_path, ("max_elevation_deg = 80.0", "max_elevation_deg = 30.0"))
    r = CliRunner().invoke(app, ["check", str(cfg)])
    assert r.exit_code == 0, r.output


@pytest.mark.parametrize(
    ("ceiling", "words"),
    [("85", "85 reaches into the keep-out cone"), ("3", "3 must be above min_elevation_deg 5")],
)
def test_a_ceiling_refused_is_said_at_its_own_key(tmp_path: Path, ceiling: str, words: str) -> None:
    """The [arm] table's own checks had blamed the table ("line 8: key 'arm'")."""
    cfg = _virtual_arm(tmp_path, ("max_elevation_deg = 80.0", f"max_elevation_deg = {ceiling}"))
    line = 1 + cfg.read_text().splitlines().index(f"max_elevation_deg = {ceiling}")
    r = CliRunner().invoke(app, ["check", str(cfg)])
    assert r.exit_code == 2, r.output
    assert f"line {line}: key 'arm.max_elevation_deg': {words}" in said(r), said(r)
