"""A Ctrl-C landing as the capture starts (after ``run`` counted the capture as begun, before
the controller's own teardown took charge of the rig) still sends the dome its all-off and
closes the rig, and is said as a stop before the first image.

``run`` marked the capture begun (``started = True``) and then called it: a stop in those
few bytecodes, or before the session's ``with`` took the rig, was answered by neither the
opening's clean-up nor the controller's teardown: the emulated dome, held open (lights off)
after ``--auto-exposure``'s metering, was neither sent an all-off nor closed. The stop is
injected exactly there: the step that follows (the use case's ``run_opened_session``)
raises KeyboardInterrupt before it does anything."""

from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS
from conftest import said as unwrapped
from typer.testing import CliRunner

import rti_rig.app.usecases.session as session_usecase
import rti_rig.runtime.controller as controller
from rti_rig.cli import app
from rti_rig.simulator.dome_firmware import DomeFirmware
from rti_rig.simulator.own_protocols import Verb


def _dome_commands(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The names of the commands the emulated dome's firmware executes from now on, in order
    (the firmware's own record: what reached the board, not what the driver meant to send)."""
    received: list[str] = []
    real_execute = DomeFirmware._execute

    def execute(self, req, now):  # type: ignore[no-untyped-def]
        received.append(req.verb)
        return real_execute(self, req, now)

    monkeypatch.setattr(DomeFirmware, "_execute", execute)
    return received


def _run_six(out: Path, *options: str) -> tuple[Any, str]:
    """``rti-rig run`` of 6 lights on the shipped emulated dome into ``out``; the result and
    what it said, unwrapped."""
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, *options, "--no-verdict"], terminal_width=400)
    return r, unwrapped(r)


def test_a_ctrl_c_as_the_capture_starts_switches_the_emulated_dome_off_and_closes_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    received = _dome_commands(monkeypatch)
    seen: dict[str, Any] = {}

    def interrupted(opened, *args: Any, **kwargs: Any) -> Any:
        seen["opened"], seen["before"] = opened, len(received)
        raise KeyboardInterrupt  # as a stop landing before the controller took the rig

    monkeypatch.setattr(session_usecase, "run_opened_session", interrupted)
    out = tmp_path / "s"
    # metered first: its teardown keeps the dome's port open (lights off) for the capture
    r, said = _run_six(out, "--auto-exposure")
    assert "opened" in seen, said
    assert seen["before"] > 0, said  # metering spoke to the dome (lit it, switched it off)
    assert Verb.ALL_OFF in received[seen["before"] :], (received, said)
    assert not seen["opened"].rig.lighting.source.link.port_open, said  # the rig was closed
    assert "Stopped (Ctrl-C) before the first image: nothing was captured" in said, said
    # what the close established of the lights, as other stops say (it had been unsaid)
    assert f"written to {out}; all-off sent and acknowledged by the dome: lights are off." in said
    assert "Traceback" not in said, said
    assert r.exit_code == 130, said
    assert not any(out.glob("image_*"))


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_sigterm_as_the_controller_checks_the_disk_switches_the_held_dome_off_and_closes_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same stop one step later: inside the capture's ``with`` (the controller checking
    the free space, before its ``try``). The ``with``'s close released the emulator alone
    (the rig's close trusts the controller to have made the devices safe), and the command,
    finding the session closed, did nothing: the held port stayed open, its all-off unsent.
    A real SIGTERM, raised in the run's own process there (no timing)."""
    received = _dome_commands(monkeypatch)
    seen: dict[str, Any] = {}
    real_run = session_usecase.run_opened_session

    def run_opened_session(opened, *args: Any, **kwargs: Any) -> Any:
        seen["opened"], seen["before"] = opened, len(received)
        return real_run(opened, *args, **kwargs)

    def check_free_space(*args: Any, **kwargs: Any) -> None:
        signal.raise_signal(signal.SIGTERM)

    monkeypatch.setattr(session_usecase, "run_opened_session", run_opened_session)
    monkeypatch.setattr(controller, "check_free_space", check_free_space)
    out = tmp_path / "s"
    r, said = _run_six(out, "--auto-exposure")
    assert "opened" in seen, said
    assert seen["before"] > 0, said  # metering spoke to the dome
    assert Verb.ALL_OFF in received[seen["before"] :], (received, said)
    assert not seen["opened"].rig.lighting.source.link.port_open, said
    assert (
        "Stopped (SIGTERM) before the first image: nothing was captured or written to "
        f"{out}; all-off sent and acknowledged by the dome: lights are off." in said
    ), said
    assert "teardown problem" not in said and "Traceback" not in said, said
    assert r.exit_code == 143, said


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_sigterm_as_the_teardown_begins_is_not_said_as_before_the_first_image(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A SIGTERM that cuts the controller's teardown before it records the run's end (raised
    where the teardown sets its hold, in its place: a stop landing before the hold is caught
    and torn down for, so this stands for one the teardown could not catch): the session's
    close makes the dome safe in its place. Every image was in, and the run had said
    "Stopped (SIGTERM) before the first image: nothing was captured", with no word of the
    images or the resume. A real SIGTERM, raised in the run's own process there (no
    timing)."""
    received = _dome_commands(monkeypatch)
    real_held = controller._teardown_held

    def teardown_held(cancel):  # type: ignore[no-untyped-def]
        received.append("capture over")
        signal.raise_signal(signal.SIGTERM)
        return real_held(cancel)

    monkeypatch.setattr(controller, "_teardown_held", teardown_held)
    out = tmp_path / "s"
    r, said = _run_six(out)
    assert len(list(out.glob("image_*"))) == 6, said
    assert "before the first image" not in said and "nothing was captured" not in said, said
    assert "Emergency stop (SIGTERM)" in said and "6 image(s) kept" in said, said
    assert f"rti-rig run --resume {out}" in said, said
    # the all-off the lights' line rests on came after the teardown was cut
    assert Verb.ALL_OFF in received[received.index("capture over") :], (received, said)
    assert "Traceback" not in said, said
    assert r.exit_code == 143, said
