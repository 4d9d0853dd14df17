"""A DNG whose colour filter array, as LibRaw reads it, has photosites of only two colours
(red and green: a CFAPattern tag damaged, or a sensor without a colour filter whose file
claims one), saved into the watched folder of the shipped folder-watch dome: ``rti-rig run``
refuses it, and its advice leads somewhere the user can go.

It had said "a monochrome camera: set [camera.device.decode] mode = "mosaic"", but a mosaic
session is one ``rti-rig fit`` refuses (its images are labelled CFA mosaics): the advice led
to a session that could never be fitted. A monochrome camera's shots are taken as 16-bit grey
TIFFs, as the refusal of a monochrome sensor's own file says. The DNG comes from the tests'
own writer (written from the TIFF and DNG specifications) with CFAPattern 0 1 0 1.
"""

from __future__ import annotations

import sys
from pathlib import Path

import dng_spec_writer
import numpy as np
import pytest
from conftest import folder_watch_config, tethered_run

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def test_run_refuses_a_cfa_of_two_colours_with_advice_that_leads_to_a_fittable_session(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    out = tmp_path / "s"
    cfg = folder_watch_config(tmp_path, tether)
    assert 'mode = "demosaic"' in cfg.read_text(encoding="utf-8")  # a colour camera
    monkeypatch.setitem(dng_spec_writer.PATTERNS, "RGRG", (0, 1, 0, 1))
    data = dng_spec_writer.dng(np.full((32, 48), 20000, np.uint16), pattern="RGRG")
    r, said, _lit_at_end = tethered_run(monkeypatch, cfg, tether, [("IMG_0001.dng", data)], out)
    assert r.exit_code != 0, said
    assert "Traceback" not in said, said
    assert f"{tether / 'IMG_0001.dng'}: " in said, said
    assert "has photosites of RG only" in said, said
    assert "copy the shot again from the camera's card" in said, said
    assert 'set [camera.device.decode] mode = "mosaic"' not in said, said
    assert "which rti-rig fit refuses" in said, said
    assert "16-bit grey TIFFs" in said and 'patterns = ["*.tif"] in [camera.device]' in said
