"""``plan --out`` and ``export-lp --out`` given a name that is not ``.lp`` write the file and say
that relight, RTIBuilder and ``rti-rig fit`` find an ``.lp`` by its name.

Why: both wrote the .lp format to ``p.txt`` without a word, and ``rti-rig fit x.txt`` then
refused it ("give a session folder or an .lp file"); relight and RTIBuilder look for ``.lp``.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

runner = CliRunner()


def test_a_plan_written_under_another_name_says_so(tmp_path: Path) -> None:
    txt = tmp_path / "p.txt"
    r = runner.invoke(app, ["plan", "--lights", "8", "--out", str(txt)])
    assert r.exit_code == 0, r.output
    assert len(read_lp(txt)) == 8
    assert f"note: {txt} holds light positions in the .lp format but is not named .lp" in said(r)
    assert "rti-rig run --plan reads it as it is" in said(r)
    assert f"name it {tmp_path / 'p.lp'} to use it there" in said(r), said(r)
    r = runner.invoke(app, ["plan", "--lights", "8", "--out", str(tmp_path / "p.lp")])
    assert r.exit_code == 0 and "not named .lp" not in said(r), r.output


def test_an_export_written_under_another_name_says_so(tmp_path: Path) -> None:
    s = tmp_path / "s"
    cfg = CONFIGS / "simulated_dome.toml"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output
    txt = s / "x.txt"
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(txt)])
    assert r.exit_code == 0, r.output
    assert len(read_lp(txt)) == 6
    assert f"note: {txt} holds light positions in the .lp format but is not named .lp" in said(r)
    assert "relight, RTIBuilder and rti-rig fit find an .lp by its name" in said(r), said(r)
    assert "run --plan" not in said(r)
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(s / "x.lp")])
    assert r.exit_code == 0 and "not named .lp" not in said(r), r.output


def test_the_lp_name_advised_says_when_a_file_has_it_already(tmp_path: Path) -> None:
    """Why: "name it p.lp to use it there" was said with p.lp already there, and a rename
    replaces it (a plan of the same object, say)."""
    kept = tmp_path / "p.lp"
    r = runner.invoke(app, ["plan", "--lights", "8", "--out", str(kept)])
    assert r.exit_code == 0, r.output
    before = kept.read_text()
    txt = tmp_path / "p.txt"

    r = runner.invoke(app, ["plan", "--lights", "9", "--out", str(txt)])

    assert r.exit_code == 0, r.output
    assert (
        f"name it {kept} to use it there ({kept} exists: a rename replaces it, so move that one "
        "aside first or choose another name ending in .lp)"
    ) in said(r), said(r)
    assert kept.read_text() == before
