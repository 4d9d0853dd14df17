"""A tethering program that saves every shot over one file name, through `rti-rig run` on the
shipped folder-watch example (its dome firmware emulated on a pty, its camera a thread that
saves a DNG into the watched folder for each shutter pulse the board saw).

``gphoto2 --capture-tethered --filename capture.dng --force-overwrite`` (or a vendor program set
to one file name) rewrites the same file in place: the same inode, a new size or time. A name
is used once, so the second shot is never taken; but the timeout asked "is the camera firing
and saving there?" of a camera that was doing both, and named nothing the user could change.
"""

from __future__ import annotations

import shutil
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, shipped_dome_on_pty
from dng_spec_writer import dng, mosaic_from_rgb
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

WATCH_CONFIG = CONFIGS / "example_dome_48_folder_watch.toml"


def _config(tmp_path: Path, tether: Path) -> Path:
    """The shipped example beside its .lp, watching ``tether``, waiting 4 s for a file."""
    shutil.copy(CONFIGS / "example_dome_48.lp", tmp_path / "example_dome_48.lp")
    text = WATCH_CONFIG.read_text()
    text = text.replace('folder = "~/Pictures/rti-tether"', f'folder = "{tether}"')
    text = text.replace("timeout_s = 15.0", "timeout_s = 4.0")
    text = text.replace("width = 6000", "width = 32").replace("height = 4000", "height = 32")
    cfg = tmp_path / "watch.toml"
    cfg.write_text(text)
    return cfg


def test_a_file_saved_over_in_place_is_named_at_the_timeout(tmp_path, monkeypatch):
    tether = tmp_path / "tether"
    tether.mkdir()
    cfg = _config(tmp_path, tether)
    shot = dng(
        mosaic_from_rgb(np.full((32, 32, 3), 0.3), "RGGB", (0,) * 4, 4095), "RGGB", (0,) * 4, 4095
    )
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        stop = threading.Event()

        def tethering_program() -> None:
            saved = 0
            while not stop.is_set():
                pulses = sum(e.what == "shutter" for e in list(firmware.history))
                if pulses > saved:
                    saved += 1
                    with open(tether / "capture.DNG", "wb") as fh:  # over the last one
                        fh.write(shot + bytes(saved))  # each shot its own size
                stop.wait(0.01)

        thread = threading.Thread(target=tethering_program, daemon=True)
        thread.start()
        out = tmp_path / "s"
        try:
            r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "3"])
        finally:
            stop.set()
            thread.join(5)
        lit_at_end = firmware.lit
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "Traceback" not in said
    assert "capture.DNG was written again" in said, said
    assert "its own file name" in said, said
    assert "is the camera firing" not in said, said
    assert lit_at_end is None and "lights are off" in said
    # the first shot, taken before it was saved over, is kept in the session
    assert (out / "raw" / "image_001.dng").read_bytes() == shot + bytes(1)
    assert "1 image(s) kept" in said
