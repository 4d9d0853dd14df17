"""A servo cable pulled mid-session is said as a lost cable or supply, not a wrong config.

Servos that had answered all along at this id and baud rate went silent (the arm's cable
pulled, its supply cut), and ``run`` ended with "COMM_RX_TIMEOUT … (check power, cabling, id
and baud rate: X-series servos ship at 57600)" during "read 122+14": advice to change a config
that was right, about a command no one can look up. A servo that has answered on the port and
stops is now said to have stopped answering, with its cable, chain and supply to check, and
the block read is named by its registers.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import inprocess_arm_config
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.cli import app


def test_a_session_whose_servos_go_silent_names_the_cable_not_the_config(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        emu, real_receive = rig.emulator, rig.emulator.receive

        def receive(data: bytes) -> bytes:
            out = real_receive(data)
            if emu.instructions_received >= 70:  # well into the session's first move
                emu.silent_ids.update(emu.servos)  # the bus cable out: no servo hears
            return out

        emu.receive = receive
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    cfg = inprocess_arm_config(tmp_path)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--out", str(out), "--lights", "6"], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code != 0, said
    assert "Traceback" not in said
    assert "has stopped answering: its cable, the chain of cables to it, or the servos' " in said
    assert "(the id and baud rate were right)" in said, said
    assert "check power, cabling, id and baud rate" not in said, said
    assert "read 122+14" not in said and "read Moving..Present Position" in said, said
