"""`export-lp` of a one-image session (a preview) says "1 light", not "1 lights"."""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_a_preview_exports_one_light(tmp_path: Path) -> None:
    session = tmp_path / "preview"
    r = runner.invoke(app, ["preview", str(CONFIGS / "virtual_arm.toml"), "--out", str(session)])
    assert r.exit_code == 0, r.output
    out = session / "one.lp"

    r = runner.invoke(app, ["export-lp", str(session), "--out", str(out)])

    assert r.exit_code == 0, r.output
    assert f"1 light → {out}" in said(r), said(r)
    assert out.read_text().splitlines()[0] == "1"
