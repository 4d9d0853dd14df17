"""A watched-folder camera whose folder is not there is refused before the dome's port opens.

The camera connects after the dome, so ``rti-rig run`` found the missing folder only once the
dome's port had opened: the Nab board resets on that opening and boots with every LED lit, then
was switched off again, for a session that could never take a picture. Through the CLI on a
user's hardware copy of the shipped Nab config, its board served on a pty as a real one is: the
board must never see its port open.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import emulated_dome_as_hardware
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


@pytest.mark.parametrize("command", ["run", "check", "preview"])
def test_a_missing_watch_folder_is_refused_before_the_dome_boots(
    tmp_path: Path, command: str
) -> None:
    board = board_for("nab-rti-v1")
    with serve_on_pty(board, "nab-rti-v1") as link:
        cfg = emulated_dome_as_hardware(tmp_path, "emulated_nab_rti_v1.toml", link.port)
        (tmp_path / "tether").rmdir()  # the tethering program's folder, not made yet
        out = ["--out", str(tmp_path / "session")] if command != "check" else []
        r = CliRunner().invoke(app, [command, str(cfg), *out], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "key 'camera.device.folder': the watched folder" in said, said
    assert f"{tmp_path / 'tether'} does not exist or is not a folder: create it" in said, said
    assert "Traceback" not in said
    # the port was never opened: the board never reset, so never booted lit
    assert not any(what == "boot" for _, what in board.events), board.events
    assert not (tmp_path / "session").exists()
