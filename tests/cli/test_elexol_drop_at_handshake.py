"""A USB drop at the Elexol board's handshake is reconnected, as every other firmware's is.

The Elexol 24R1 is an FTDI board: opening its port resets nothing and it prints no banner, so
its first byte is the answer to the handshake ``?``. A port dropped at that first command had
failed the run at once (exit 2, a raw "all off after the failed connection … port not open"
log line and an empty "capturing 0/6" bar), because the connect reopened only a board heard
from before the drop. A board that boots dark cannot have browned its port out by lighting at
the opening, so it is now reopened within the config's reconnect window.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.slow  # real firmware timing over a pty, and one USB drop of 1 s
@pytest.mark.pty
@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_an_elexol_port_dropped_at_its_handshake_is_reconnected(tmp_path: Path) -> None:
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        (CONFIGS / "emulated_elexol.toml").read_text()
        + '\n[[emulator.faults]]\nat_command = 1\nkind = "disconnect"\n'
    )
    out = tmp_path / "S"
    r = CliRunner().invoke(app, ["run", str(cfg), "--lights", "6", "--out", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "0/6" not in said and "port not open" not in said, said
    assert "6 image(s) in the session" in said, said
    assert (out / "lights.lp").is_file()


@pytest.mark.slow  # real firmware timing over a pty, and the whole reconnect window (7.5 s)
@pytest.mark.pty
@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_an_elexol_port_that_does_not_come_back_is_said_once_with_no_empty_bar(
    tmp_path: Path,
) -> None:
    """The drop outlasts the reconnect window: the run fails (exit 2) saying the port was lost,
    the lights line says the all-off could not be sent because the port had not come back (not
    the link's "port not open (connect first)", nor a log line saying it besides), and no empty
    "capturing 0/6" bar stands above "Nothing was captured"."""
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        (CONFIGS / "emulated_elexol.toml").read_text()
        + '\n[[emulator.faults]]\nat_command = 1\nkind = "disconnect"\ndelay_s = 60.0\n'
    )
    out = tmp_path / "S"
    r = CliRunner().invoke(app, ["run", str(cfg), "--lights", "6", "--out", str(out)])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "0/6" not in said and "port not open" not in said, said
    assert "all off after the failed connection" not in said, said
    assert "All-off could NOT be sent (the dome's port was lost and had not come back)" in said
    assert "Nothing was captured" in said and "port was lost during the handshake" in said
    assert "Traceback" not in said
