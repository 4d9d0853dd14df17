"""A stopped command's exit code is decided on the signal that stopped it, carried typed from
the handler (``EmergencyStop.signum``), not on the words that name the stop.

Why: ``stop_exit_code`` compared the words with ``"SIGTERM"``: a stop named otherwise (a
handler's own words, a rewording) exited 130 as a Ctrl-C, where the shell's convention for a
SIGTERM is 143."""

from __future__ import annotations

import signal
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from tests.conftest import said

REPO = Path(__file__).resolve().parents[2]


def test_a_sigterm_named_in_other_words_still_exits_143(monkeypatch: pytest.MonkeyPatch) -> None:
    from rti_rig.runtime.controller import EmergencyStop
    from rti_rig.simulator.sim_lights import SimulatedArm

    real_move = SimulatedArm.move_to
    moves: list[int] = []

    def move_to(self, direction):  # type: ignore[no-untyped-def]
        moves.append(1)
        if len(moves) == 2:  # during the check's walk, as the check's handler raises it
            raise EmergencyStop(signal.SIGTERM, "terminated by the lab's scheduler")
        return real_move(self, direction)

    monkeypatch.setattr(SimulatedArm, "move_to", move_to)
    r = CliRunner().invoke(app, ["check", str(REPO / "rig_configs" / "virtual_arm.toml")])
    text = said(r)
    assert r.exit_code == 143, text
    assert "Check stopped (terminated by the lab's scheduler)" in text, text


@pytest.mark.parametrize(
    ("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGHUP, 129)]
)
def test_the_exit_code_is_128_plus_the_signals_number(signum: signal.Signals, code: int) -> None:
    from rti_rig.cli.app import stop_exit_code

    assert stop_exit_code(signum) == code
