"""An Elexol 24R1 board whose answer to ``?`` comes with one byte damaged on the line.

The board prints no boot banner, so its ``?`` answer is the first thing it says. A damaged
first answer (``USB I/\\x0e 24R1``) had failed the check and the run at once, with "check the
port, the baud rate and the protocol profile" (the config was right), where a lost one is
resent; ``rti-rig probe`` said "No known dome firmware answered". Now the connect resends the
``?`` (it lights nothing), the probe asks again, and a board whose answers keep coming damaged
is sent to its cable. Through the CLI, against the board's emulator (the shipped config's
``[[emulator.faults]]``, or the emulator served on a pty as a real board is).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.led_dome.damaged_reply import one_byte_off
from rti_rig.simulator.dome_firmware import Fault, FaultKind, FaultPlan
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _garbled_at(tmp_path: Path, *commands: int) -> Path:
    cfg = tmp_path / "rig.toml"
    faults = "".join(
        f'\n[[emulator.faults]]\nat_command = {n}\nkind = "garble_reply"\n' for n in commands
    )
    cfg.write_text((CONFIGS / "emulated_elexol.toml").read_text() + faults)
    return cfg


def test_a_first_answer_damaged_is_asked_again_and_the_check_goes_on(tmp_path: Path) -> None:
    cfg = _garbled_at(tmp_path, 1)
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "LEDs stepped: 12, sent without error: 12, failed: 0" in said, said
    assert "recovery: 1 retries" in said, said
    assert "check the port, the baud rate" not in said, said


def test_answers_that_stay_damaged_send_the_user_to_the_cable_not_the_config(
    tmp_path: Path,
) -> None:
    cfg = _garbled_at(tmp_path, 1, 2, 3)
    out = tmp_path / "session"
    r = CliRunner().invoke(app, ["run", str(cfg), "--out", str(out)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "the expected reply with one byte damaged); gave up after 3 attempts" in said, said
    assert "check the USB cable" in said, said
    assert "check the port, the baud rate" not in said, said
    assert "Traceback" not in said
    assert not out.exists() or not any(out.rglob("*.png")), said


def test_probe_asks_again_when_the_answer_came_damaged() -> None:
    board = board_for("elexol-24r1", faults=FaultPlan((Fault(1, FaultKind.GARBLE_REPLY),)))
    with serve_on_pty(board, "elexol-24r1") as link:
        r = CliRunner().invoke(app, ["probe", link.port], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "Found: elexol-24r1" in said, said
    assert "its first answer came with one byte damaged on the line" in said, said


def test_what_counts_as_one_byte_off() -> None:
    wanted = re.compile(r"USB I/O 24R1\r\n")
    assert one_byte_off(wanted, "USB I/\x0e 24R1\r\n")  # replaced
    assert one_byte_off(wanted, "USB IO 24R1\r\n")  # lost
    assert one_byte_off(wanted, "USB I/O 2\x844R1\r\n")  # added
    assert not one_byte_off(wanted, "USB I/\x0e 2\x0eR1\r\n")  # two bytes
    # what a wrong baud rate makes of the answer, and another firmware's text
    assert not one_byte_off(wanted, "\xf8\x80\x1e\x98\xe6\x00\xf8\x1e\x86\xe0\x98\x80\r")
    assert not one_byte_off(wanted, "<All lights turned off.>")
    # a short acknowledgement is one replacement from almost any text: never taken
    assert not one_byte_off(re.compile("OK"), "OX")
