"""A file option given a path ending in ``/`` is refused, naming it: the user named a folder.

``Path("plans/")`` is ``Path("plans")``: ``plan … --out plans/`` with no folder ``plans``
wrote the plan as a file named ``plans`` and said it had planned into it.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

DOME = str(CONFIGS / "simulated_dome.toml")


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["plan", DOME, "--out", "plans/"], "--out"),
        (["plan", DOME, "--out", "p.lp", "--figure", "maps/"], "--figure"),
        (["export-lp", "session", "--out", "lps/"], "--out"),
        (["lights-from-sphere", "session", "--sphere", "1,1,1", "--out", "domes/"], "--out"),
        (["calibrate-lights", "card", "--rig", DOME, "--out", "cal/"], "--out"),
    ],
)
def test_a_file_option_ending_in_a_slash_is_refused_before_anything_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, args: list[str], option: str
) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output
    given = args[args.index(option) + 1]
    assert f"{option} {given}: ends in '/', which names a folder" in said(result), said(result)
    assert f"({option} {given}NAME)" in said(result)
    assert list(tmp_path.iterdir()) == []


def test_a_folder_option_may_end_in_a_slash(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``fit``'s and ``run``'s ``--out`` name folders: a trailing ``/`` is how many users
    write one, and is not refused."""
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, ["fit", "no-such-session", "--out", "fits/"])
    assert result.exit_code == 2, result.output
    assert "names a folder" not in said(result)
    assert "no-such-session" in said(result), said(result)


def test_file_options_show_file_in_help() -> None:
    result = CliRunner().invoke(app, ["plan", "--help"])
    assert result.exit_code == 0
    rows = {ln.split()[1]: ln.split()[2] for ln in result.output.splitlines() if "│ --" in ln}
    assert rows["--out"] == rows["--figure"] == "FILE", rows
