"""``--auto-exposure`` on a watched-folder camera is refused before anything opens, through the
front door, naming the file, the key and what to do.

A watched folder only receives what the camera, set by hand or by its own program, shot: rti-rig
does not set its exposure. Metering on the shipped folder-watch dome pulsed the camera for test
shots at exposures it could not take and stopped at the second with "set the camera to manual
at the session exposure", an exposure the metering was still looking for.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import at_key
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
WATCH = REPO / "rig_configs" / "example_dome_48_folder_watch.toml"
runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


@pytest.mark.parametrize("command", [["run", "--lights", "4"], ["preview"]])
def test_auto_exposure_on_a_watched_folder_is_refused_naming_the_key(
    tmp_path: Path, command: list[str]
) -> None:
    out = tmp_path / "s"
    verb, *rest = command
    r = runner.invoke(app, [verb, str(WATCH), "--out", str(out), *rest, "--auto-exposure"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"{at_key(WATCH, 'camera.device.kind')}" in text
    assert "--auto-exposure cannot meter a 'folder_watch' camera" in text
    assert "Drop --auto-exposure" in text and "exposure_s" in text
    # refused before the dome's port was looked for, and nothing written
    assert "open port" not in text and not out.exists()


def test_check_auto_exposure_on_a_watched_folder_is_refused_as_run_refuses_it() -> None:
    """`rti-rig check --auto-exposure` checks the rig for `run --auto-exposure`: a camera that
    run refuses to meter is refused by the check too, before the dome's port is looked for."""
    r = runner.invoke(app, ["check", str(WATCH), "--auto-exposure"])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert f"{at_key(WATCH, 'camera.device.kind')}" in text
    assert "--auto-exposure cannot meter a 'folder_watch' camera" in text
    assert "open port" not in text and "Traceback" not in text
