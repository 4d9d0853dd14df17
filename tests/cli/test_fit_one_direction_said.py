"""Lights all at one direction are said to be bunched there, not to lie in some plane.

Four lights straight overhead (a dome driven to its zenith LED four times) were refused by
``rti-rig fit --model ps`` as lights that "lie (nearly) in one upright plane through the
object: lights at one azimuth (90° or 270°)": the singular values of one repeated direction
are exactly 0 twice, and the test for "bunched" was strict, so a plane was picked at random.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, write_lp


@pytest.mark.parametrize(
    ("direction", "said"),
    [
        ((0.0, 0.0, 1.0), "they are bunched at the zenith"),
        (
            (
                np.cos(np.radians(40.0)) * np.cos(np.radians(30.0)),
                np.cos(np.radians(40.0)) * np.sin(np.radians(30.0)),
                np.sin(np.radians(40.0)),
            ),
            "they are bunched about one direction (azimuth 30°, elevation 40°)",
        ),
    ],
)
def test_one_repeated_direction_is_said_bunched(
    tmp_path: Path, direction: tuple[float, float, float], said: str
) -> None:
    entries = [LpEntry(f"img_{i}.png", direction) for i in range(4)]
    rng = np.random.default_rng(1)
    for e in entries:
        cv2.imwrite(str(tmp_path / e.name), rng.integers(40, 200, (8, 8), dtype=np.uint8))
    lp = tmp_path / "acq.lp"
    write_lp(lp, entries)
    r = CliRunner().invoke(app, ["fit", str(lp), "--out", str(tmp_path / "f"), "--model", "ps"])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, text
    assert "cannot determine a surface normal" in text and said in text, text
    assert "plane" not in text, text
