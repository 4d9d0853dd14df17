"""`rti-rig export-lp` of a session shot with ``decode.mode = "mosaic"`` says that its images
are CFA mosaics, through the CLI on the shipped DSLR example (its dome firmware emulated on a
pty, python-gphoto2 replaced at its API boundary by tests/fake_gphoto2.py).

``rti-rig fit`` refuses such a session by name, but export-lp wrote its .lp for relight and
RTIBuilder without a word: given it, they fit grey checkerboards (one colour per pixel) as if
they were pictures.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from dng_spec_writer import dng, mosaic_from_rgb
from fake_gphoto2 import Body, make_module
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _config(tmp_path: Path, mode: str) -> Path:
    """The shipped DSLR example beside its .lp, its RAWs decoded with ``mode``."""
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (CONFIGS / "example_dome_48.toml").read_text()
    text = text.replace('mode = "demosaic"', f'mode = "{mode}"')
    text = text.replace("width = 6000", "width = 48").replace("height = 4000", "height = 32")
    cfg = tmp_path / f"dslr_{mode}.toml"
    cfg.write_text(text)
    return cfg


def _raw(body: Body | None = None) -> bytes:
    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (32, 48, 3))
    return dng(mosaic_from_rgb(np.array(rgb), "RGGB", (0,) * 4, 4095), "RGGB", (0,) * 4, 4095)


@pytest.mark.parametrize("mode", ["mosaic", "demosaic"])
def test_export_lp_of_a_mosaic_session_says_its_images_are_not_pictures(
    tmp_path, monkeypatch, mode
):
    cfg = _config(tmp_path, mode)
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(Body(render=_raw)))
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(
            app, ["run", str(cfg), "--out", str(out), "--lights", "4", "--no-verdict"]
        )
    assert r.exit_code == 0, r.output
    # the run's next step: no fit of mosaics (it had named the fit, which refuses them)
    next_said = " ".join(r.output.split()).split("Next: ", 1)[1]
    if mode == "mosaic":
        assert next_said.startswith('no fit of CFA mosaics (decode.mode = "mosaic")'), next_said
        assert str(out / "raw") in next_said
    else:
        assert next_said.startswith(f"rti-rig fit {out} --out {out}-fit"), next_said
    lp = out / "export.lp"
    r = CliRunner().invoke(app, ["export-lp", str(out), "--out", str(lp)])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert lp.is_file() and "4 lights" in said
    if mode == "demosaic":
        assert "CFA mosaic" not in said, said
        return
    assert "4 of the 4 images listed are CFA mosaics" in said, said
    assert "relight or RTIBuilder" in said and "raw/ folder" in said, said
    assert 'decode.mode = "demosaic" or "half"' in said, said
