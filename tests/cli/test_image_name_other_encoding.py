"""An image whose file is there with its name in Windows-1252 bytes, where the `.lp` names it
in UTF-8, is named as such with the rename that fixes it: it had been called missing (QA,
2026-12-05), beside the file a file manager shows with that very name."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay" / "dirs.lp"

pytestmark = pytest.mark.skipif(
    sys.platform != "linux", reason="a name's bytes as they are: Linux file names"
)


def test_a_name_in_windows_1252_bytes_is_named_with_the_rename(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    acq.mkdir()
    lines = ACQ.read_text().splitlines()[1:13]
    names = [line.split()[0] for line in lines]
    for name in names[1:]:
        shutil.copyfile(ACQ.parent / name, acq / name)
    # the first image under a name the .lp writes in UTF-8, its file's bytes Windows-1252
    shutil.copyfile(ACQ.parent / names[0], os.fsdecode(os.fsencode(acq) + b"/pi\xe8ce.jpg"))
    lines[0] = "pièce.jpg " + " ".join(lines[0].split()[1:])
    (acq / "lights.lp").write_text("12\n" + "\n".join(lines) + "\n", encoding="utf-8")
    r = CliRunner().invoke(
        app, ["fit", str(acq / "lights.lp"), "--out", str(tmp_path / "f")], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "pièce.jpg is there with Windows-1252 bytes in the file name, not UTF-8" in said, said
    assert "convmv -f cp1252 -t utf-8" in said and "Traceback" not in said, said
