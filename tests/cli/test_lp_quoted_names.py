"""An `.lp` whose image names are in quotes (``"my image 01.jpg" x y z``, as a script's CSV
writer quotes a field with spaces): the images are named as quoted, with the one edit that
makes the file read, where they had been told to be copied "where their names point" beside
the very files the user sees."""

from __future__ import annotations

import shutil
from pathlib import Path

from conftest import REPO, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_quoted_names_are_said_with_the_fix_and_read_once_unquoted(tmp_path: Path) -> None:
    acq = tmp_path / "acq"
    shutil.copytree(REPO / "tests" / "data" / "neuralrti_replay", acq)
    lines = (acq / "dirs.lp").read_text().splitlines()
    quoted = [lines[0]]
    for line in lines[1:]:
        name, *xyz = line.split()
        spaced = name.replace("image", "my image ")
        (acq / name).rename(acq / spaced)
        quoted.append(f'"{spaced}" ' + " ".join(xyz))
    (acq / "dirs.lp").write_text("\n".join(quoted) + "\n")
    lp = str(acq / "dirs.lp")

    for argv, code in ((["check", lp], 1), (["run", lp, "--out", str(tmp_path / "s")], 2)):
        r = runner.invoke(app, argv)
        text = said(r)
        assert r.exit_code == code, text
        assert '18 of them are named in quotes ("my image 01.jpg"' in text
        assert "remove the quotes from the .lp" in text
        assert "copy them where their names point" not in text
        assert "Traceback" not in r.output
    assert not (tmp_path / "s").exists()

    # the edit it asks for is all it takes
    (acq / "dirs.lp").write_text("\n".join(q.replace('"', "") for q in quoted) + "\n")
    r = runner.invoke(app, ["check", lp])
    assert r.exit_code == 0 and "RESULT: PASS" in said(r), said(r)


def test_a_quoted_name_beside_a_missing_one_is_said_with_both_ways_out(tmp_path: Path) -> None:
    """One name in quotes (its file there) and one whose file is gone: the quotes' edit alone
    had been offered, as if it found both ("1 of them are named in quotes"), and the missing
    image's way out was left unsaid."""
    acq = tmp_path / "acq"
    shutil.copytree(REPO / "tests" / "data" / "neuralrti_replay", acq)
    lines = (acq / "dirs.lp").read_text().splitlines()
    name, *xyz = lines[1].split()
    (acq / name).rename(acq / name.replace("image", "my image "))
    lines[1] = f'"{name.replace("image", "my image ")}" ' + " ".join(xyz)
    gone = lines[2].split()[0]
    (acq / gone).unlink()
    (acq / "dirs.lp").write_text("\n".join(lines) + "\n")

    r = runner.invoke(app, ["check", str(acq / "dirs.lp")])
    text = said(r)
    assert r.exit_code == 1, text
    assert '1 of them is named in quotes ("my image 01.jpg") and its file' in text
    assert "remove the quotes from the .lp" in text
    assert "for the other 1 not found, copy them where their names point" in text
    assert "Traceback" not in r.output
