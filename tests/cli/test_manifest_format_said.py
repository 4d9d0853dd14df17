"""A manifest whose "format" key was deleted or edited is said as such, with what to do: "unknown
session format None" had been all a resume, export-lp or fit was told."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.parametrize(
    ("fmt", "words"),
    [
        (None, 'has no "format" key'),
        ("rti-rig-session/9", 'says format "rti-rig-session/9"'),
        (3, "says format 3"),
    ],
)
def test_a_manifest_of_no_known_format_is_said_with_the_mend(
    tmp_path: Path, fmt: object, words: str
) -> None:
    session = tmp_path / "s"
    session.mkdir()
    manifest = {"schedule": {"steps": []}} | ({} if fmt is None else {"format": fmt})
    (session / "manifest.json").write_text(json.dumps(manifest))
    (session / "journal.jsonl").write_text("")
    for argv in (
        ["run", "--resume", str(session)],
        ["export-lp", str(session), "--out", str(tmp_path / "x.lp")],
    ):
        r = CliRunner().invoke(app, argv)
        assert r.exit_code == 2, r.output
        text = said(r)
        assert f'manifest.json {words}, not "rti-rig-session/1"' in text, text
        assert "restore manifest.json from a backup copy of the folder" in text, text
        assert ("newer rti-rig" in text) == (fmt == "rti-rig-session/9"), text
