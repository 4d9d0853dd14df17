"""RAW files watched in a folder whose name is not UTF-8 (a tethering share on an old NAS named
in Latin-1), their session kept beside them: ``rti-rig run`` on the shipped folder-watch dome
reads each file's capture time and decodes it.

rawpy hands LibRaw a ``str`` path encoded as UTF-8, which such a name (a lone surrogate in
Python) cannot be: its UnicodeEncodeError had been taken for a file still being written (the
capture time waited ``timeout_s`` for it, then was said missing), then ended the run at the
decode as an "unexpected" fault. LibRaw is given such a file's bytes instead. The config kept
beside them is named through ``shown_path`` where the run asks for its frame size to be set.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import NOT_UTF8_NAME, folder_watch_config, tethered_run
from dng_spec_writer import dng, mosaic_from_rgb

from rti_rig.core.shell_words import shown_path

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def test_run_takes_a_raw_saved_into_a_folder_whose_name_is_not_utf8(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    odd = tmp_path / os.fsdecode(NOT_UTF8_NAME)
    tether = odd / "tether"
    tether.mkdir(parents=True)
    # the config names the folder relative to where rti-rig runs (TOML holds UTF-8 only)
    cfg = folder_watch_config(odd, Path("tether"))
    monkeypatch.chdir(odd)
    out = odd / "s"
    mosaic = mosaic_from_rgb(np.full((32, 48, 3), 0.3), "RGGB", (0,) * 4, 4095)
    shot = dng(mosaic, "RGGB", (0,) * 4, 4095, date_time="2026:12:02 08:00:00")
    name = os.fsdecode(b"caf\xe9_0001.dng")  # the file's own name is Latin-1 too
    r, said, lit_at_end = tethered_run(monkeypatch, cfg, tether, [(name, shot)], out, lights=1)
    assert r.exit_code == 0, said
    journal = (out / "journal.jsonl").read_text()
    assert "holds no capture time" not in said and "holds no capture time" not in journal, said
    assert len(list((out / "linear").glob("image_*.tif"))) == 1, said
    # the config's frame size (6000 x 4000) is told to be put right in it, named as it pastes
    assert f"camera.width x camera.height in {shown_path(cfg)} say 6000 x 4000" in said, said
    assert "\udce9" not in said, said
    assert (tether / name).read_bytes() == shot  # left as the program saved it
    assert lit_at_end == []
