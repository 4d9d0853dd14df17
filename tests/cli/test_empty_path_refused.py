"""An empty path on the command line (a script's unset ``"$part"``) is refused, naming it.

``Path("")`` is the current folder: ``run --out ""`` in an empty folder wrote the session into
it, and in any other folder was refused as ". is not empty", naming no empty argument.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.parametrize(
    "args",
    [
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out", "", "--lights", "6"],
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out=", "--lights", "6"],
        ["run", "--resume", ""],
        ["preview", str(CONFIGS / "simulated_dome.toml"), "--out", ""],
        ["fit", "somewhere", "", "--out", "fits"],
    ],
)
def test_an_empty_path_is_refused_before_anything_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, args: list[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output
    assert "an empty path" in said(result)
    assert list(tmp_path.iterdir()) == []


def test_the_current_folder_written_as_a_dot_is_still_a_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "kept.txt").write_text("x")
    result = CliRunner().invoke(
        app, ["run", str(CONFIGS / "simulated_dome.toml"), "--out", ".", "--lights", "6"]
    )
    assert result.exit_code == 2, result.output
    assert "is not empty" in said(result)
    assert "an empty path" not in said(result)
    # the new folder it offers is the current one's sibling, by its absolute path (`.` has
    # no name to add -2 to: the offer had ended in "unexpected ValueError")
    assert f"--out {tmp_path}-2" in said(result), said(result)
    assert [p.name for p in tmp_path.iterdir()] == ["kept.txt"]
