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
    assert board.lit == frozenset()  # the truth: booted lit, then switched off
