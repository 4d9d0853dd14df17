"""Ctrl-C twice while ``rti-rig run --auto-exposure`` connects the Nab dome (metering opens
the rig before the session): the first in the board's boot wait, the second while the all-off
that answers the first waits for the board to finish booting.

The second Ctrl-C had cut that all-off short: the board, which lights every LED as it boots,
was left lit whole (the message said so). Further signals are now held until the all-off is
through, then acted on. The Ctrl-Cs are real SIGINTs raised at those two points (no race)."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, emulators_built_by_check
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.led_dome.scripted import ScriptedDomeDriver


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_second_ctrl_c_while_the_interrupted_connect_switches_off_waits_for_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    emulators = emulators_built_by_check(monkeypatch)
    real_wait = ScriptedDomeDriver._wait_ready
    waits: list[int] = []

    def wait_ready(self, deadline, already):  # type: ignore[no-untyped-def]
        waits.append(1)
        if len(waits) <= 2:  # the boot wait, then the stopped connect's wait before its all-off
            signal.raise_signal(signal.SIGINT)
        return real_wait(self, deadline, already)

    monkeypatch.setattr(ScriptedDomeDriver, "_wait_ready", wait_ready)
    cfg = CONFIGS / "emulated_nab_rti_v1.toml"
    out = tmp_path / "session"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--auto-exposure", "--out", str(out)], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert len(waits) >= 2 and r.exit_code == 130, said
    assert "Traceback" not in said
    assert "all-off sent and acknowledged by the dome: lights are off" in said, said
    assert "power supply" not in said
    (board,) = emulators
    assert any(what == "boot" for _, what in board.events)
    assert board.lit_once_booted() == frozenset()  # the truth: booted lit, then switched off


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_while_a_failed_connect_reopens_at_the_published_rate_waits_for_its_all_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``baudrate = 115200`` on the Nab board (9600): the connect fails, and the port is reopened
    at 9600 to send the all-off, which resets the board (lit whole while it boots). One Ctrl-C
    as that reopening opens the port had cut the all-off short: exit 130, the board reset by
    our own reopen and never switched off, the user told to cut its supply. The Ctrl-C is now
    held until the all-off is through, then acted on. A real SIGINT, raised at that point."""
    from rti_rig.drivers.led_dome.dome_profiles import nab_rti_v1
    from rti_rig.drivers.led_dome.transport import SerialTransport
    from rti_rig.simulator.domes.nab_rti_v1 import NabRtiV1Board

    emulators = emulators_built_by_check(monkeypatch)
    real_open = SerialTransport.open
    stops: list[int] = []

    def open_port(self):  # type: ignore[no-untyped-def]
        real_open(self)
        if self.baudrate == 9600 and not stops:  # the reopening at the published rate
            stops.append(signal.SIGINT)
            signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(SerialTransport, "open", open_port)
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    text = text.replace('profile = "nab-rti-v1"', 'profile = "nab-rti-v1"\nbaudrate = 115200')
    # shorter waits than the real ones (each boot and wait is spent twice, in real time), each
    # with a margin of about 1 s over what it waits for, so that a loaded machine's stalled
    # emulator thread still answers in time: a quicker bootloader than the Uno's 1.6 s, a boot
    # wait 1.2 s past it and the banner, and the all-off's reply timeout (1 s in the profile)
    # kept at 1 s, where a booted board at the right rate answers within 30 ms and one at the
    # wrong rate never does
    monkeypatch.setattr(NabRtiV1Board, "boot_s", 0.4)
    monkeypatch.setitem(nab_rti_v1.ALL_OFF["reply"], "timeout_s", 1.0)
    text = text.replace("reply_timeout_s = 3.0", "reply_timeout_s = 1.0")
    text = text.replace("led_count = 12", "led_count = 12\nboot_wait_s = 1.6")
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text)
    out = tmp_path / "session"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--auto-exposure", "--out", str(out)], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert stops and r.exit_code == 130, said
    assert "Traceback" not in said
    assert "reopened at 9600 baud" in said and "was acknowledged: lights are off" in said, said
    assert "power supply" not in said, said
    (board,) = emulators
    assert [what for _, what in board.events].count("boot") == 2  # our reopen reset it
    assert board.lit_once_booted() == frozenset()  # booted lit, then switched off


def test_run_help_says_a_stop_while_connecting_first_switches_the_dome_off() -> None:
    """``--help`` had said only "Ctrl-C twice or SIGTERM stops at once", while a stop during the
    dome's connect waits for the all-off (docs/domes.md)."""
    r = CliRunner().invoke(app, ["run", "--help"], terminal_width=400)
    said = " ".join(r.output.replace("│", " ").split())
    assert r.exit_code == 0, said
    assert "A stop while the dome connects first switches the dome off" in said, said
    assert "a further Ctrl-C waits for it" in said, said
