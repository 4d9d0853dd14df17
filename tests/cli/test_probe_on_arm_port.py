"""``rti-rig probe`` pointed at a Dynamixel arm's port (probe is for finding a dome firmware).

Servos answer only their own packets (Protocol 2.0: header FF FF FD 00), which no probe sends;
a Dynamixel ping is not sent either, since its bytes could be keys to a dome that never answers.
The user is told that no dome firmware answered and that an arm's port answers none of the
probes, with the command that does talk to an arm; no traceback, no hang, nothing the servos
take as an instruction."""

from __future__ import annotations

import sys

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import SystemClock
from rti_rig.simulator.dynamixel_emulator import arm_settings_of, served_arm


@pytest.mark.slow  # every probe listens in real time: about 25 s in all
@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_probe_on_an_arms_port_says_no_dome_answered_and_points_to_check() -> None:
    settings, _ = arm_settings_of(None)
    with served_arm(settings, SystemClock()) as (server, emulator):
        assert server.device_path is not None
        r = CliRunner().invoke(app, ["probe", server.device_path], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "Traceback" not in said
    assert isinstance(r.exception, SystemExit)  # the exit code, not a Python error
    assert "No known dome firmware answered" in said, said
    assert "A servo arm's port (Dynamixel servos) answers none of these probes" in said, said
    assert "run rti-rig check on its rig config" in said
    assert emulator.instructions == []  # no byte of the probes made a servo packet
