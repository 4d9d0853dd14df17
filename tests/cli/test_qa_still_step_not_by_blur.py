"""A session that held still is not called moved part-way because moving images back blurs them.

The move part-way check (rti_rig.reconstruct.qa._confirmed_step) confirms the edges' step when
the images, moved back by it, are explained better by a fit. Moving back by a fraction of a
pixel interpolates, and bilinear interpolation is a blur that lowers the pixel noise the
residual measures. On the shipped simulated dome's tablet at 1024 px and 24 lights, which held
still, the edges' 1.1 px step (its shading edges move with the light) read 0.72 of the residual
as captured once moved back (a half-pixel blur: 0.71), and the verdict was "reshoot:
image_002 ... image_024 (23 images: object or camera moved from image_002 on ...)". Both
hypotheses are now compared on equally interpolated images; a real move is still named from
its first image on (tests/cli/test_qa_move_part_way.py).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import dome_session
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.slow
def test_a_still_tablet_at_1024_px_is_good(tmp_path: Path) -> None:
    session = dome_session(tmp_path, "tablet", 1024, 24)
    out = tmp_path / "fit"
    r = runner.invoke(
        app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh", "--no-normals"]
    )
    assert r.exit_code == 0, r.output
    qa = json.loads((out / "qa.json").read_text())
    assert qa["good"], qa["verdict"]
    assert "moved" not in qa["verdict"], qa["verdict"]
