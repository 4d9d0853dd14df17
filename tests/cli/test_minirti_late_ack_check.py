"""Through ``rti-rig check`` on the shipped minirti config: the board acknowledges one light
late (after the reply timeout) and never acknowledges the command resent for it. The late
``0x01`` had been counted as the resent command's acknowledgement: one retry was said, and a
light the board never acknowledged passed as acknowledged. Now that resend times out too and is
sent once more (two retries), and the check still passes on acknowledgements that are each
their own command's."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
runner = CliRunner()


def test_a_late_ack_is_not_counted_for_the_resent_light(tmp_path: Path) -> None:
    text = (CONFIGS / "emulated_minirti.toml").read_text(encoding="utf-8")
    assert "reply_timeout_s = 3.0" in text
    faults = (
        "\n[emulator]\nfaults = [\n"
        # after the 3 s timeout, 1.5 s from either edge of the 3 s more the driver waits for
        # it (nearer an edge, a loaded machine could move it across)
        '  {at_command = 2, kind = "delay_reply", delay_s = 4.5},\n'
        '  {at_command = 3, kind = "drop_reply"},  # the resent light: taken, not acknowledged\n'
        "]\n"
    )
    cfg = write_config(tmp_path, text + faults)
    r = runner.invoke(app, ["check", str(cfg)])
    out = said(r)
    assert r.exit_code == 0, out
    assert "recovery: 2 retries, 0 reconnects" in out
    assert "acknowledged by the board: 12, failed: 0" in out
    assert "lights: all-off sent and acknowledged by the dome: lights are off" in out
