"""A dome whose firmware has no handshake, back on USB after a drop with an LED lit, is not
said to have answered nor to be off again until something established it.

hadrian2/RTI_Dome never replies and minirti's host sends no handshake (dome-firmwares.md):
reopening their port exchanges nothing. The run had said "The dome is back: its port reopened
and it answered", and its error "the dome is off again", while nothing had been sent since the
port came back; of the RTI_Dome board its lights line said in the same output that the closing
all-off was not confirmed. The Nab sketch's reconnection sends its init all-off, which the
board acknowledges, so there both are established (tests/cli/test_dome_reconnect_said.py).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.slow,  # real firmware timing over a pty, and a USB drop of 1 s
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
]


def _run_dropped_with_led_lit(tmp_path: Path, config: str, at_command: int) -> tuple[int, str]:
    cfg = tmp_path / "rig.toml"
    fault = f'[[emulator.faults]]\nat_command = {at_command}\nkind = "disconnect"\n'
    cfg.write_text((CONFIGS / config).read_text() + "\n" + fault)
    argv = ["run", str(cfg), "--lights", "2", "--out", str(tmp_path / "S"), "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    return r.exit_code, said(r)


def test_the_never_answering_rti_dome_is_not_said_to_answer_or_be_off(tmp_path: Path) -> None:
    # command 3: the all-off after LED 0's image (1: connect all-off, 2: light LED 0)
    code, text = _run_dropped_with_led_lit(tmp_path, "emulated_rti_dome.toml", 3)
    assert code == 2, text
    assert re.search(
        r"LED 0 \(az [-\d.]+°, el [-\d.]+°\) was meant to be lit when the port went", text
    ), text
    assert "it answered" not in text, text
    assert "The dome is back: its port reopened after " in text, text
    assert "the dome is off again" not in text, text
    assert "whether the dome is dark is what the closing all-off established" in text, text
    assert "this firmware never acknowledges, so lights are most likely off" in text, text


def test_the_minirti_dome_is_said_off_by_its_acknowledged_closing_all_off(
    tmp_path: Path,
) -> None:
    # command 4: the all-off after LED 0's image (1, 2: the connect's all-offs, 3: LED 0)
    code, text = _run_dropped_with_led_lit(tmp_path, "emulated_minirti.toml", 4)
    assert code == 2, text
    assert re.search(
        r"LED 0 \(az [-\d.]+°, el [-\d.]+°\) was meant to be lit when the port went", text
    ), text
    assert "it answered" not in text, text
    assert "the dome is off again" not in text, text
    assert "whether the dome is dark is what the closing all-off established" in text, text
    assert "All-off sent and acknowledged by the dome: lights are off." in text, text
