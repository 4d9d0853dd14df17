"""``rti-rig probe`` given a path that is no serial port, and the case of its error line.

A regular file, a folder or ``/dev/null`` given as the port had been told to check that the
dome is plugged in and powered: the path was the mistake, and the probe now says what the path
is. Its error line read "ERROR:" where every other command says "error:".
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _path(kind: str, folder: Path) -> Path:
    if kind == "file":
        (folder / "rig.toml").write_text('name = "a config, not a port"\n')
        return folder / "rig.toml"
    return folder if kind == "folder" else Path("/dev/null")


@pytest.mark.parametrize(
    ("kind", "what"),
    [
        ("file", "is a regular file"),
        ("folder", "is a folder"),
        ("/dev/null", "is a device but not a terminal"),
    ],
)
def test_a_path_that_is_no_serial_port_is_named_as_such(
    tmp_path: Path, kind: str, what: str
) -> None:
    port = _path(kind, tmp_path)
    r = runner.invoke(app, ["probe", str(port)])
    text = said(r)
    assert r.exit_code == 1, text
    assert f"{port} {what}: it is not a serial port, so no firmware was asked" in text, text
    assert "plugged in" not in text and "profile =" not in text, text
    assert "error: cannot open serial port" in text and "ERROR" not in text, text


def test_a_missing_port_keeps_the_advice_to_check_its_name_and_the_dome(tmp_path: Path) -> None:
    r = runner.invoke(app, ["probe", str(tmp_path / "ttyACM9")])
    text = said(r)
    assert r.exit_code == 1, text
    assert "error: cannot open serial port" in text and "ERROR" not in text, text
    assert "that the dome is plugged in and powered" in text, text
    assert "is not a serial port" not in text, text
