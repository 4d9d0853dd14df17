"""``fit --out DIR`` into a folder that is not empty names a folder that is free.

Before: "DIR is not empty: fit writes into a new or empty folder", and the user found a name;
``run``'s refusal of such an --out names one ("such as --out DIR-2, which does not exist yet").
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_fit_into_a_folder_in_use_names_a_free_one(tmp_path: Path) -> None:
    session = tmp_path / "s"
    r = runner.invoke(
        app, ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(session), "--no-verdict"]
    )
    assert r.exit_code == 0, said(r)
    out = tmp_path / "f"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    (tmp_path / "f-2").mkdir()  # taken too: the name offered is one not there

    r = runner.invoke(app, ["fit", str(session), "--out", str(out), "--model", "ps"])

    assert r.exit_code == 2, said(r)
    assert f"choose another --out (such as --out {tmp_path / 'f-3'}, which does not" in said(r)
    assert [p.name for p in out.iterdir()] == ["notes.txt"]
    r = runner.invoke(app, ["fit", str(session), "--out", str(tmp_path / "f-3"), "--model", "ps"])
    assert r.exit_code == 0, said(r)  # the folder named, pasted, is taken
