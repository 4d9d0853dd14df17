"""A tethered DSLR unplugged while a shot's RAW is downloaded, through `rti-rig run` on the
shipped DSLR example (its dome firmware emulated on a pty, python-gphoto2 replaced at its
API boundary by tests/fake_gphoto2.py), then `--resume` once it is plugged back in.

The shot is taken; its download, or the wait for the body's announcement of its files, fails
with libgphoto2's -7 (I/O error), and every call after it too. The stop said only "the camera
stopped answering during 'download' … Images already taken are kept": nothing of the shot
just taken, lost with the camera's RAM or left on its card (never deleted before it is
downloaded).
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


def _config(tmp_path: Path, target: str) -> Path:
    """The shipped DSLR example beside its .lp, small frames, shooting into ``target``."""
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = (CONFIGS / "example_dome_48.toml").read_text()
    old = 'capture_target = "Internal RAM"'
    assert old in text
    text = text.replace(old, f'capture_target = "{target}"')
    text = text.replace("width = 6000", "width = 48").replace("height = 4000", "height = 32")
    cfg = tmp_path / "dslr.toml"
    cfg.write_text(text)
    return cfg


def _raw(body: Body) -> bytes:
    rgb = np.broadcast_to(np.array([0.2, 0.5, 0.8]), (32, 48, 3))
    return dng(mosaic_from_rgb(np.array(rgb), "RGGB", (0,) * 4, 4095), "RGGB", (0,) * 4, 4095)


@pytest.mark.parametrize("target", ["Internal RAM", "Memory card"])
@pytest.mark.parametrize("op", ["file_get", "wait_for_event"])
def test_a_camera_unplugged_at_a_download_says_where_the_shot_is_and_the_resume_shoots_it(
    tmp_path, monkeypatch, target, op
):
    """Unplugged at the third shot's download, or as the body announces its files (the
    event wait after the capture returned): the third shot is taken, never downloaded."""
    cfg = _config(tmp_path, target)
    body = Body(render=_raw, off_at_call=(op, 3))
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(body))
    out = tmp_path / "s"
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "4"])
        lit_at_end = firmware.lit
    said = " ".join(r.output.split())
    assert r.exit_code == 2 and "Traceback" not in said and lit_at_end is None, said
    assert body.shots == 3, body.shots
    assert f"stopped answering during '{'download' if op == 'file_get' else op}'" in said, said
    assert "This shot was taken but its file" in said and "IMG_0003.CR2" in said, said
    assert "the resume shoots it again" in said and "rti-rig run --resume" in said, said
    if target == "Internal RAM":
        assert "so it is lost: /IMG_0003.CR2 existed only there" in said, said
    else:
        assert "stays on the camera's card at /store_00020001/DCIM/100CANON/IMG_0003.CR2" in said
        assert "IMG_0003.CR2" in body.card and "IMG_0003.CR2" not in body.deleted
    assert (out / "lights.lp").read_text().split()[0] == "2"
    assert sorted(p.name for p in (out / "raw").glob("*.cr2")) == [
        "image_001.cr2",
        "image_002.cr2",
    ]

    body.switch_on()  # plugged back in
    with shipped_dome_on_pty(monkeypatch, cfg):
        r = CliRunner().invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, " ".join(r.output.split())
    assert (out / "lights.lp").read_text().split()[0] == "4"
    for k in range(1, 5):
        assert (out / f"raw/image_{k:03d}.cr2").read_bytes() == _raw(body)
