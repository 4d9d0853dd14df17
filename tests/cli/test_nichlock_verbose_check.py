"""A nichlock board whose verbose serial output is on (its settings menu's option 4, kept in
EEPROM) says its shutter inside each step's reply: ``LED number: N; on pin P``, then ``Shutter
turning on at: S seconds(Mms)``, then the ``>`` prompt (``shutterCtrl.cpp``'s ``setShutter``).
The profile read a step's reply only as the LED line straight before the prompt, so every
step of such a board failed as an unreadable reply ("check the port, the baud rate and the
profile") though it had stepped as asked. ``rti-rig check`` on that board, through real
pyserial, passes now and leaves it dark."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import emulated_dome_as_hardware, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.simulator.domes.nichlock import NichlockBoard
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
runner = CliRunner()


def test_check_passes_on_a_verbose_nichlock_board(tmp_path: Path) -> None:
    board = NichlockBoard(verbose=True)
    with serve_on_pty(board, "nichlock") as link:
        cfg = emulated_dome_as_hardware(tmp_path, "emulated_nichlock.toml", link.port)
        r = runner.invoke(app, ["check", str(cfg)])
        out = said(r)
        assert r.exit_code == 0, out
        assert "LEDs stepped: 12, acknowledged by the board: 12, failed: 0" in out
        assert "RESULT: PASS" in out
        assert "all-off sent and acknowledged by the dome: lights are off" in out
        assert board.lit == frozenset()
