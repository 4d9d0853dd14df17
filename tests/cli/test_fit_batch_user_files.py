"""A batch never throws away files it did not write in a session's output folder.

A refit (the session changed since its fit) removed the earlier fit's folder whole, with a
user's notes put in it; and a folder of the session's name holding files but no fit was
"skipped (finished earlier)", exit 0 ("every fit is written"), with no fit anywhere. Now the
earlier fit is kept beside the new one when it holds such files, and a folder that is no fit
fails its session (exit 2), left as it is; an empty one is fitted into.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def batch(*sources: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit S... --out OUT`` as a user runs it (PS: any light count from 3 fits)."""
    args = ["fit", *map(str, sources), "--out", str(out), "--model", "ps", "--no-qa"]
    return runner.invoke(app, args, terminal_width=400)


def _sessions(tmp_path: Path) -> tuple[Path, Path]:
    cfg = write_config(tmp_path, SMALL_DOME)
    s, t = tmp_path / "S", tmp_path / "T"
    for session in (s, t):
        r = runner.invoke(app, ["run", str(cfg), "--out", str(session), "--lights", "6"])
        assert r.exit_code == 0, r.output
    return s, t


@pytest.mark.e2e
def test_a_refit_keeps_the_earlier_folder_holding_a_users_files(tmp_path: Path) -> None:
    s, t = _sessions(tmp_path)
    fb = tmp_path / "FB"
    assert batch(s, t, out=fb).exit_code == 0
    (fb / "S" / "notes.txt").write_text("varnish lifting at lower left\n")
    tif = s / "linear" / "image_003.tif"
    data = bytearray(tif.read_bytes())
    data[-100] ^= 0xFF  # changed since capture: refitted
    tif.write_bytes(bytes(data))
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 0, r.output
    assert f"{s}: refitted (its session changed since the earlier fit" in text, text
    kept = fb / "S-earlier-fit"
    assert (
        "its earlier fit's folder held files the fit had not written (notes.txt): it is kept, "
        f"with them, as {kept}" in text
    ), text
    assert (kept / "notes.txt").read_text() == "varnish lifting at lower left\n"
    assert (fb / "S" / "fit.json").is_file() and not (fb / "S" / "notes.txt").exists()
    # a refit of a folder holding only what the fit wrote keeps nothing aside
    data[-100] ^= 0x0F
    tif.write_bytes(bytes(data))
    r = batch(s, t, out=fb)
    assert r.exit_code == 0 and "held files" not in said(r), r.output
    assert sorted(p.name for p in fb.iterdir()) == ["S", "S-earlier-fit", "T"]


@pytest.mark.e2e
def test_a_folder_that_is_no_fit_fails_its_session_and_is_left_as_it_is(tmp_path: Path) -> None:
    s, t = _sessions(tmp_path)
    fb = tmp_path / "FB"
    (fb / "S").mkdir(parents=True)
    (fb / "S" / "notes.txt").write_text("important\n")
    (fb / "T").mkdir()  # made ahead, empty: fitted into
    r = batch(s, t, out=fb)
    text = said(r)
    assert r.exit_code == 2, r.output
    assert f"{s}: failed: {fb / 'S'} holds files but no fit (no fit.json: notes.txt)" in text
    assert f"{t}: done" in text, text
    assert sorted(p.name for p in (fb / "S").iterdir()) == ["notes.txt"]
    assert (fb / "T" / "fit.json").is_file()
