"""`[scene] raw = true` on a frame of odd width or height is refused when the config loads.

The simulated DSLR path encodes each frame as a 2x2 Bayer mosaic; at 101 x 77 px the session
started, then stopped at its first capture with "unexpected ValueError: mosaic sizes must be
even for a 2×2 CFA ... please report it".
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.errors import ConfigError

runner = CliRunner()


@pytest.mark.parametrize(("width", "height"), [(101, 78), (100, 77)])
def test_an_odd_raw_frame_is_refused_at_load(tmp_path: Path, width: int, height: int) -> None:
    text = SMALL_DOME.replace("width = 64\nheight = 64", f"width = {width}\nheight = {height}")
    cfg = write_config(tmp_path, text + "raw = true\n")
    with pytest.raises(ConfigError) as err:
        load_rig_config(cfg)
    assert "rig.toml" in str(err.value) and f"got {width} x {height}" in str(err.value)
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "3"])
    assert r.exit_code == 2, r.output
    assert "2x2 Bayer mosaic" in r.output and "unexpected" not in r.output, r.output
    assert not (tmp_path / "s").exists()


def test_an_even_raw_frame_runs(tmp_path: Path) -> None:
    text = SMALL_DOME.replace("width = 64\nheight = 64", "width = 64\nheight = 48")
    cfg = write_config(tmp_path, text + "raw = true\n")
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "3"])
    assert r.exit_code == 0, r.output
    assert len(list((tmp_path / "s" / "linear").glob("image_*.tif"))) == 3
