"""`run --out FILE` (or a folder under a file) is refused by name before the rig opens, worded
as `fit` and `bench` word it.

It had said "FILE exists and is not a folder: choose another --out", and for `FILE/sub`
"cannot write FILE/sub: Not a directory (ENOTDIR)", while fit and bench said "is a file: give
a folder" for the same slip.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app

RIG = Path(__file__).resolve().parents[2] / "rig_configs" / "simulated_dome.toml"


@pytest.mark.parametrize("under", [False, True])
def test_run_out_a_file_is_refused_as_a_file(tmp_path: Path, under: bool) -> None:
    a_file = tmp_path / "notes.txt"
    a_file.write_text("kept\n")
    out = a_file / "session" if under else a_file
    r = CliRunner().invoke(app, ["run", str(RIG), "--out", str(out), "--lights", "6"])
    text = " ".join(r.output.split())
    assert r.exit_code == 2, (text, r.exception)
    if under:
        assert f"--out {out}: {a_file} is a file, not a folder: give a folder" in text, text
    else:
        assert f"--out {a_file} is a file: give a folder" in text, text
    assert "Traceback" not in text
    assert a_file.read_text() == "kept\n"
