"""`rti-rig plan` says how to shoot a preview within the band as a command that pastes.

Why: a preview shot at 55° planned with `--max-elevation-deg 45` was told "`rti-rig preview
RIG --out P --max-elevation-deg 45` shoots one within the band": pasted, `RIG` was refused as
no rig file, and with the rig filled in the preview went to a folder named P. The command now
names the rig config given to plan and a folder beside the plan that does not exist yet.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
from conftest import CONFIGS, said
from PIL import Image
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

runner = CliRunner()
RIG = CONFIGS / "simulated_dome.toml"


def test_the_preview_within_the_band_is_offered_as_a_command_that_runs(tmp_path: Path) -> None:
    folder = tmp_path / "plans é x"
    folder.mkdir()
    shade = np.linspace(40, 200, 64, dtype=np.float64)
    Image.fromarray(np.tile(shade, (64, 1)).astype(np.uint8)).save(folder / "preview.png")

    r = runner.invoke(
        app,
        [
            "plan", str(folder / "preview.png"), "--rig", str(RIG), "--preview-light", "112.5,55",
            "--max-elevation-deg", "45", "--out", str(folder / "plan.lp"),
        ],
    )  # fmt: skip

    assert r.exit_code == 0, r.output
    text = said(r)
    found = re.search(r"`(rti-rig preview [^`]*)` shoots one within the band", text)
    assert found is not None, text
    words = shlex.split(found.group(1))
    assert words[2:] == [str(RIG), "--out", str(folder / "preview"), "--max-elevation-deg", "45"]
    shot = runner.invoke(app, words[1:])  # pasted: the preview is shot within the band
    assert shot.exit_code == 0, shot.output
    (light,) = read_lp(folder / "preview" / "lights.lp")
    assert light.direction[2] <= np.sin(np.radians(45.0)) + 1e-9
