"""A finished session whose ``lights.lp`` was cut short, emptied or had a line deleted since.

Its resume had called it intact ("every image is as captured … nothing was changed. Next:
rti-rig fit"), and the fit then refused the file with advice that deletes a light ("a title
or a row of column headings? … delete the line") or, emptied, with none. Both now name the
mend: the listing written again from the journal, which the resume never does on its own (a
complete session's resume changes nothing). Where the journal's lights were edited too, that
mend would write them, so a backup is named instead.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
LIGHTS = 8


@pytest.fixture(scope="module")
def finished(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.mktemp("finished")
    cfg = write_config(base, SMALL_DOME)
    out = base / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", str(LIGHTS)])
    assert r.exit_code == 0, r.output
    return out


def _damage(lp: Path, how: str) -> None:
    data = lp.read_bytes()
    if how == "cut":
        cut = data.index(b"image_005") + len(b"image_0")  # mid-line, as a copy cut short
        lp.write_bytes(data[:cut])
    elif how == "emptied":
        lp.write_bytes(b"")
    else:  # a light's line deleted
        lines = data.splitlines(keepends=True)
        lp.write_bytes(b"".join([lines[0], *lines[1:3], *lines[4:]]))


def test_an_intact_listing_is_not_doubted(finished: Path, tmp_path: Path) -> None:
    out = tmp_path / "s"
    shutil.copytree(finished, out)
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    assert "not the listing" not in said(r) and "export-lp" not in said(r), r.output


@pytest.mark.parametrize("how", ["cut", "emptied", "line deleted"])
def test_a_damaged_listing_is_named_with_its_mend_which_works(
    finished: Path, tmp_path: Path, how: str
) -> None:
    out = tmp_path / "s"
    shutil.copytree(finished, out)
    lp = out / "lights.lp"
    _damage(lp, how)
    damaged = lp.read_bytes()

    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output  # complete all the same: every image is as captured
    text = said(r)
    assert "but its lights.lp is not the listing rti-rig wrote from journal.jsonl" in text, text
    mend = f"rti-rig export-lp {out} --out {lp}"
    kept = "write it again from the journal (the present one is kept in recovered/)"
    assert f"{kept}: {mend}" in text, text
    assert lp.read_bytes() == damaged  # a resume of a complete session changes nothing

    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    if how != "line deleted":  # a listing that cannot be read: refused, with the same mend
        assert r.exit_code == 2, r.output
        text = said(r)
        assert "it is the session's listing of the lights that fired" in text, text
        assert mend in text and "delete the line" not in text, text
    else:  # read, and judged wrong by the verdict (tests/cli/test_resume_edited_lights_lp.py)
        assert "lights.lp wrong" in said(r), r.output

    r = runner.invoke(app, mend.split()[1:])  # the mend, as said: it had been refused
    assert r.exit_code == 0, r.output
    assert lp.read_bytes() == (finished / "lights.lp").read_bytes()
    (kept_lp,) = (out / "recovered").glob("*/lights.lp")  # the damaged one, never lost
    assert kept_lp.read_bytes() == damaged
    assert f"the one there is kept as {kept_lp}" in said(r), r.output
    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0 and "not the listing" not in said(r), r.output


def test_a_journal_whose_lights_were_edited_too_is_not_listed_again(
    finished: Path, tmp_path: Path
) -> None:
    """The journal's light of image_003 edited as well: a listing written from it would carry
    the edit, so the mend named is the folder's backup."""
    out = tmp_path / "s"
    shutil.copytree(finished, out)
    journal = out / "journal.jsonl"
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    records[2]["actual_direction"] = [0.0, 0.0, 1.0]
    journal.write_text("".join(json.dumps(r) + "\n" for r in records))

    r = runner.invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "journal.jsonl does not give every image the light manifest.json records" in text
    assert "restore the folder from a backup copy" in text and "export-lp" not in text, text
