"""`rti-rig plan --out` names what is in the way when the plan cannot be written there.

Why: the plan is written as a temporary file renamed over ``--out``; with --force onto a named
pipe or a device (``/dev/full``) it said "Planned 12 lights → /dev/full" and left a plain file
where the device had been. And ``--out notes.lp/plan.lp`` said "folder notes.lp does not exist;
create it first" of a file that exists.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
RIG = CONFIGS / "simulated_dome.toml"


def _plan(out: Path, *extra: str) -> tuple[int, str]:
    r = runner.invoke(app, ["plan", "--rig", str(RIG), "--out", str(out), *extra])
    return r.exit_code, said(r)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes are POSIX")
def test_a_pipe_is_not_replaced_even_with_force(tmp_path: Path) -> None:
    pipe = tmp_path / "plan pipe.lp"
    os.mkfifo(pipe)

    code, text = _plan(pipe, "--force")

    assert code == 2, text
    assert "is not a regular file (a device, a pipe or a socket)" in text, text
    assert "Planned" not in text, text
    assert stat.S_ISFIFO(pipe.lstat().st_mode)


def test_a_file_in_the_way_of_the_folder_is_said_to_be_a_file(tmp_path: Path) -> None:
    notes = tmp_path / "notes.lp"
    notes.write_text("mine\n")

    code, text = _plan(notes / "plan.lp")

    assert code == 2, text
    assert f"{notes} is a file, not a folder" in text, text
    assert "does not exist" not in text, text
    assert notes.read_text() == "mine\n"
