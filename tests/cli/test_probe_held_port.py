"""``rti-rig probe`` on a port another program holds says so, not "check the dome's cable".

While a ``check`` ran on a dome, ``probe`` on its port said "The port could not be opened …
Check the port's name, that the dome is plugged in and powered" (QA, 2026-12-05): the dome
was plugged in, and being driven.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
import serial
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
]


def test_probe_on_a_held_port_says_another_program_holds_it(tmp_path: Path) -> None:
    master, slave = os.openpty()
    port = os.ttyname(slave)
    holder = serial.Serial(port, exclusive=True)  # as another rti-rig holds a dome's port
    try:
        r = CliRunner().invoke(app, ["probe", port])
    finally:
        holder.close()
        os.close(master)
        os.close(slave)
    text = said(r)
    assert r.exit_code == 1, text
    assert "Another program holds the port" in text, text
    assert f"`fuser {port}`" in text, text
    assert "plugged in" not in text and "profile =" not in text, text
