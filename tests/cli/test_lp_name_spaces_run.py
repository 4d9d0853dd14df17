"""An image named with a run of spaces, listed so in its .lp, is said to be there.

An .lp's names are read as relight reads them, each run of spaces as one, so `img  01.jpg`
is looked for as `img 01.jpg`. It had been said missing under that name, with the advice to
copy it where it already was (QA, 2026-12-06).
"""

from __future__ import annotations

import shutil
from pathlib import Path

from typer.testing import CliRunner

from rti_rig.cli import app

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"


def _checked(tmp_path: Path, on_disk: str, listed: str):  # type: ignore[no-untyped-def]
    """`check` of the acquisition with image01.jpg renamed ``on_disk`` and listed ``listed``."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    (acq / "image01.jpg").rename(acq / on_disk)
    lp = acq / "dirs.lp"
    lp.write_text(lp.read_text(encoding="utf-8").replace("image01.jpg", listed))
    return CliRunner().invoke(app, ["check", str(lp)], terminal_width=4000)


def test_a_name_with_a_run_of_spaces_is_named_with_the_file_that_is_there(
    tmp_path: Path,
) -> None:
    r = _checked(tmp_path, "img  01.jpg", "img  01.jpg")
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "(img 01.jpg); 'img 01.jpg' is there as 'img  01.jpg': an .lp's names are read" in (
        r.output.replace("\n", " ")
    ), r.output
    assert "copy them where their names point" not in said, said


def test_a_no_break_space_is_not_said_to_be_a_run_of_spaces(tmp_path: Path) -> None:
    """The hint is for runs of spaces or tabs only: a no-break space in the file's name is not
    what the reading collapses, and saying so would be wrong."""
    r = _checked(tmp_path, "img\u00a001.jpg", "img 01.jpg")
    assert r.exit_code == 1, r.output
    assert "(img 01.jpg)" in r.output and "each run of spaces" not in r.output, r.output
