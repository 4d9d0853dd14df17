"""`rti-rig check` stopped by SIGTERM or Ctrl-C goes through its teardown and says what it
knows about the lights. Without a handler SIGTERM killed the process at once: the emulated
RTI v1.0 sketch was left with an LED lit and nothing was printed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from conftest import emulators_built_by_check

REPO = Path(__file__).resolve().parents[2]
#: the CLI with the dome's third ``light`` holding (its LED lit) until a signal ends it
STALL_AT_THIRD_LED = """
import sys, time
from rti_rig.runtime.dome_policy import DomePolicy
real = DomePolicy.light
def light(self, index, intensity=1.0):
    real(self, index, intensity)
    if index == 2:
        print("LIT 2", file=sys.stderr, flush=True)
        end = time.monotonic() + 60.0
        while time.monotonic() < end:
            time.sleep(0.05)
DomePolicy.light = light
from rti_rig.cli import app
app(sys.argv[1:], prog_name="rti-rig")
"""


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
@pytest.mark.parametrize(
    ("sig", "code", "name"),
    [
        (signal.SIGTERM, 143, "SIGTERM"),
        (signal.SIGINT, 130, "Ctrl-C"),
        # a hang-up (the terminal or ssh connection closing) is torn down as SIGTERM is; it had
        # no handler: the process died at once, LED lit, nothing said
        (signal.SIGHUP, 129, "SIGHUP"),
    ],
)
def test_a_stopped_check_switches_the_dome_off_and_says_so(sig, code, name) -> None:
    cfg = REPO / "rig_configs" / "emulated_nab_rti_v1.toml"
    proc = subprocess.Popen(
        [sys.executable, "-c", STALL_AT_THIRD_LED, "check", str(cfg)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "COLUMNS": "200"},
    )
    assert proc.stderr is not None
    watchdog = threading.Timer(180.0, proc.kill)  # a child that stalls fails, not hangs
    watchdog.start()
    for line in proc.stderr:  # the third LED is lit and its firmware has acknowledged it
        if line.startswith("LIT 2"):
            break
    else:
        raise AssertionError(f"the walk never reached the third LED: {proc.communicate()}")
    proc.send_signal(sig)
    out, errs = proc.communicate(timeout=120)
    watchdog.cancel()
    said = " ".join((out + errs).split())
    assert proc.returncode == code, said
    assert "Traceback" not in said
    assert f"Check stopped ({name})" in said, said
    # what the teardown established (the sketch acknowledges its all-off), never "never
    # reached" for a dome whose port was open
    assert "never reached" not in said
    assert "all-off sent and acknowledged" in said, said


def test_a_stopped_arm_check_says_what_its_teardown_could_not_do(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A stop during an arm's walk goes through the lamp-off and stop; what failed there is
    said before the line that refers to it (it had been dropped with the self-test's report)."""
    from typer.testing import CliRunner

    from rti_rig.cli import app
    from rti_rig.core.errors import DeviceError
    from rti_rig.runtime.controller import EmergencyStop
    from rti_rig.simulator.sim_lights import SimulatedArm

    real_move = SimulatedArm.move_to
    moves: list[int] = []

    def move_to(self, direction):  # type: ignore[no-untyped-def]
        moves.append(1)
        if len(moves) == 2:
            raise EmergencyStop(signal.SIGTERM)
        return real_move(self, direction)

    def lamp(self, on):  # type: ignore[no-untyped-def]
        if not on and len(moves) >= 2:  # the teardown's lamp-off, after the stop
            raise DeviceError("lamp relay", "no answer to lamp off")

    monkeypatch.setattr(SimulatedArm, "move_to", move_to)
    monkeypatch.setattr(SimulatedArm, "lamp", lamp)
    r = CliRunner().invoke(
        app, ["check", str(REPO / "rig_configs" / "virtual_arm.toml")], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 143, said
    assert "teardown problem: lamp off" in said and "no answer to lamp off" in said, said
    assert said.index("teardown problem") < said.index("Check stopped (SIGTERM)")
    # the lights line does not claim the lamp-off that failed ("lamp off and stop were
    # requested" had been said of it), and says what that leaves
    assert "lamp off and stop were requested" not in said, said
    assert (
        "Check stopped (SIGTERM): stop was requested, but the lamp-off failed (not sent, or "
        "sent and not acknowledged): the lamp may still be lit" in said
    ), said


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_inside_the_opening_of_the_nab_port_still_switches_the_board_off(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Ctrl-C while pyserial opens the dome's port (after the system opened it, which resets
    the board; pyserial closes it again as the stop goes through): the port is opened again and
    the all-off sent once the board has booted. No all-off had been sent, the user told "the
    dome was never reached", and the Nab sketch, reset by the opening, stood with every LED lit.
    The Ctrl-C is a real SIGINT through the check's handler, raised at that point (no race)."""
    import serial
    from typer.testing import CliRunner

    from rti_rig.cli import app

    real_open = serial.serial_for_url
    stops: list[int] = []

    def opened(*args, **kwargs):  # type: ignore[no-untyped-def]
        port = real_open(*args, **kwargs)
        if not stops:  # the user's one Ctrl-C, in the first opening
            stops.append(signal.SIGINT)
            try:
                signal.raise_signal(signal.SIGINT)
            except BaseException:
                port.close()  # as pyserial's own open does when a stop goes through it
                raise
        return port

    monkeypatch.setattr(serial, "serial_for_url", opened)
    emulators = emulators_built_by_check(monkeypatch)
    cfg = REPO / "rig_configs" / "emulated_nab_rti_v1.toml"
    r = CliRunner().invoke(app, ["check", str(cfg)])
    said = " ".join(r.output.split())
    assert stops and r.exit_code == 130, said
    assert "Traceback" not in said
    assert "never reached" not in said, said
    assert "Check stopped (Ctrl-C): all-off sent and acknowledged by the dome" in said, said
    (board,) = emulators
    assert any(what == "boot" for _, what in board.events)  # the opening did reset it
    assert board.lit_once_booted() == frozenset()  # booted lit, then switched off
