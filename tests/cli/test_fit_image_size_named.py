"""A fit refused for an image of another size names that image.

"images of S/lights.lp differ in shape: [(400, 400, 3), (512, 512, 3)]" named no file: a user
had to open every image to find the one replaced. Through ``rti-rig fit`` on a session whose
linear TIFF of one image was replaced by a smaller one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import tifffile
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_the_image_of_another_size_is_named(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s = tmp_path / "S"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    tif = s / "linear" / "image_003.tif"
    h, w = tifffile.imread(tif).shape[:2]
    tifffile.imwrite(tif, np.full((h // 2, w // 2, 3), 1000, dtype=np.uint16), photometric="rgb")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")], terminal_width=400)
    text = said(r)
    assert r.exit_code == 2 and "Traceback" not in text, r.output
    assert f"5 are {w}×{h}×3 (width × height × channels), but linear/image_003.tif " in text, text
    assert f"({w // 2}×{h // 2}×3) is not" in text, text
