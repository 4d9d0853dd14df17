"""A dome port held by another program (another `rti-rig check` or `run`) is said as such.

The second check on a dome's port said "the dome's port could not be opened (… another program
holds it …); check that the board is plugged in and that the rig config's port names it" and,
for the lights, "if the dome is lit from an earlier run, switch it off at its power supply":
advice that cuts the power under the session that holds the port.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import serial
from conftest import emulated_dome_as_hardware
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty and flock tested on Linux"),
    pytest.mark.pty,
]


def test_a_check_on_a_port_another_program_holds_says_to_wait_for_it(tmp_path: Path) -> None:
    board = board_for("elexol-24r1")
    with serve_on_pty(board, "elexol-24r1") as link:
        cfg = emulated_dome_as_hardware(tmp_path, "emulated_elexol.toml", link.port)
        holder = serial.Serial(link.port, 38400, timeout=0, exclusive=True)  # the other program
        try:
            r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
        finally:
            holder.close()
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "the dome's port is held by another program" in said, said
    assert "let it finish or stop it with Ctrl-C" in said
    assert "the lights are that program's" in said
    assert "switch it off at its power supply" not in said
    assert "check that the board is plugged in" not in said
