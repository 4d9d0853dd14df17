"""``rti-rig fit FOLDER`` of a folder without lights.lp holding more than one ``.lp``.

It had been fitted from the first ``.lp`` in name order: an acquisition folder with its
``dirs.lp`` and a 4-light ``a_subset.lp`` beside it was fitted from the subset, verdict
"good", not a word said. Which ``.lp`` lists the folder's lights cannot be told, so it is now
refused, naming them and the command that fits the one meant; with one ``.lp`` it is fitted.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("lpchoice")
    cfg = write_config(base, SMALL_DOME)
    out = base / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "8", "--no-verdict"])
    assert r.exit_code == 0, r.output
    return out


def _subset(lp: Path, dest: Path, n: int) -> None:
    lines = lp.read_text().splitlines()
    dest.write_text("\n".join([str(n), *lines[1 : n + 1]]) + "\n")


def test_a_folder_with_two_lp_files_and_no_lights_lp_is_refused(
    session: Path, tmp_path: Path
) -> None:
    acq = tmp_path / "acq"
    acq.mkdir()
    for jpg in session.glob("image_*.jpg"):
        shutil.copy(jpg, acq / jpg.name)
    shutil.copy(session / "lights.lp", acq / "dirs.lp")
    _subset(session / "lights.lp", acq / "a_subset.lp", 4)
    r = runner.invoke(app, ["fit", str(acq), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2, r.output
    assert "2 .lp files and no lights.lp (a_subset.lp, dirs.lp)" in said(r)
    assert f"rti-rig fit {acq / 'a_subset.lp'} --out DIR" in said(r)
    assert not (tmp_path / "fit").exists()
    r = runner.invoke(app, ["fit", str(acq / "dirs.lp"), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    (acq / "a_subset.lp").unlink()  # one .lp: it is the folder's
    r = runner.invoke(app, ["fit", str(acq), "--out", str(tmp_path / "fit1")])
    assert r.exit_code == 0, r.output


def test_a_session_without_its_lights_lp_and_two_others_names_the_rebuild(
    session: Path, tmp_path: Path
) -> None:
    s = tmp_path / "s"
    shutil.copytree(session, s)
    _subset(s / "lights.lp", s / "first4.lp", 4)
    (s / "lights.lp").rename(s / "all.lp")
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 2, r.output
    assert "(all.lp, first4.lp)" in said(r)
    assert f"rti-rig export-lp {s} --out {s / 'lights.lp'}" in said(r)
