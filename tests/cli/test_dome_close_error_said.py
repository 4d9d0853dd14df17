"""A dome port that does not close cleanly is said in words, once, naming the dome and what
to do; never as a raw record.

Before, the dome's close logged "error while closing the port" at warning level, which the
command line (configuring no logging) printed raw on stderr, after the progress bar or the
check's lines, in a log record's bare form. The close still never raises it (it must not mask
the error that led to a close): it is said through the dome's listener (``run``, ``check``),
or with none as a warning record that the command line says as a note.
"""

from __future__ import annotations

import json
import logging
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
]


@pytest.fixture
def close_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    """The dome's port closes (its descriptor released), then reports an I/O error, as a
    port whose USB adapter went away while it was being closed may."""
    from rti_rig.drivers.led_dome.transport import SerialTransport

    real = SerialTransport.close

    def close(self: SerialTransport) -> None:
        was_open = self._ser is not None
        real(self)
        if was_open:
            raise OSError(5, "Input/output error")

    monkeypatch.setattr(SerialTransport, "close", close)


WORDS = "its port did not close cleanly"


def _line(text: str) -> str:
    """The line that says it, from the dome's name ("dome on PORT (…)") to its advice."""
    at = text.index(WORDS)
    start = text.rindex("dome on ", 0, at)
    end = text.index("plug it in again.", at) + len("plug it in again.")
    return text[start:end]


def _loud(caplog: pytest.LogCaptureFixture) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_port_that_does_not_close_cleanly_is_said_once(
    tmp_path: Path, close_fails: None, caplog: pytest.LogCaptureFixture, command: str
) -> None:
    argv = [command, str(CONFIGS / "emulated_dome.toml")]
    if command == "run":
        argv += ["--lights", "3", "--out", str(tmp_path / "S"), "--no-verdict"]
    with caplog.at_level(logging.DEBUG):
        r = CliRunner().invoke(app, argv, terminal_width=400)
    text = said(r)
    line = _line(text)
    assert line.endswith(
        f"{WORDS}: [Errno 5] Input/output error. It is opened anew when next needed; if "
        "that fails, unplug the dome's USB cable and plug it in again."
    ), line
    assert "(emulated" in line.split(WORDS)[0], line  # the dome, by its port and firmware
    assert text.count(WORDS) == 1, text
    assert not _loud(caplog), _loud(caplog)
    assert "error while closing the port" not in text and "WARNING:" not in text, text


def test_a_close_failing_alike_again_is_said_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The port is closed again (a second close, a reconnection's attempts): the same failure
    is said once, kept once, and the repeat goes to the log's diagnostics."""
    from rti_rig.app.dome_factory import build_dome
    from rti_rig.core.clock import VirtualClock
    from rti_rig.drivers.led_dome import DomeSerialSettings
    from rti_rig.simulator.dome_firmware import InProcessDomeTransport, firmware_for

    clock = VirtualClock()
    settings = DomeSerialSettings(port="emulated", profile="default")
    firmware = firmware_for(settings, clock=clock, led_count=8, boot_delay_s=0.2)
    dome = build_dome(settings, clock, transport=InProcessDomeTransport(firmware))
    heard: list[str] = []
    dome.listen(heard.append)
    dome.connect()

    def close() -> None:
        raise OSError(5, "Input/output error")

    monkeypatch.setattr(dome.link, "close", close)
    dome.close()
    dome.close()
    assert len(heard) == 1 and WORDS in heard[0], heard
    assert dome.close_errors == heard


def test_a_run_s_port_close_failure_is_in_its_teardown_failures(
    tmp_path: Path, close_fails: None
) -> None:
    """The run's record keeps what its teardown's close said (the manifest's
    ``teardown_failures`` had said nothing went wrong), in the shape of every teardown failure;
    it is said once, and the session, its all-off acknowledged, is not called unsafe."""
    out = tmp_path / "S"
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "3", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    text = said(r)
    assert r.exit_code == 0, text
    failures = json.loads((out / "manifest.json").read_text())["runner"]["teardown_failures"]
    assert failures == [f"port close: {_line(text)}"], failures
    assert text.count(WORDS) == 1, text
    assert "known safe state" not in text and "teardown problem" not in text, text
    assert "acknowledged" in text, text  # the lights' line says what the all-off established


NO_RECORD = "the port's close failure above is in no session record"


def _run_three(out: Path, *more: str) -> tuple[int, str]:
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "3", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict", *more], terminal_width=400)
    return r.exit_code, said(r)


def test_a_port_close_in_a_run_whose_end_a_stop_cut_is_recorded_on_disk(
    tmp_path: Path, close_fails: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A SIGTERM that cuts the controller's teardown (raised where it sets its hold, in its
    place: a stop before the hold is caught and torn down for, so this stands for one the
    teardown could not catch): the session's close makes the dome safe and closes its port
    in the teardown's stead, and records the run's cut end. The port's close failure is in
    that record as the teardown's own would be (it had been said and in no record), said
    once, and is no teardown problem."""
    import signal

    import rti_rig.runtime.controller as controller

    real_held = controller._teardown_held

    def teardown_held(cancel):  # type: ignore[no-untyped-def]
        signal.raise_signal(signal.SIGTERM)
        return real_held(cancel)

    monkeypatch.setattr(controller, "_teardown_held", teardown_held)
    out = tmp_path / "S"
    code, text = _run_three(out)
    assert code == 143, text
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["end_cut"] is True, runner
    assert runner["teardown_failures"] == [f"port close: {_line(text)}"], runner
    assert text.count(WORDS) == 1, text
    assert "teardown problem" not in text and NO_RECORD not in text, text
    assert "all-off sent and acknowledged by the dome: lights are off" in text, text


def test_metering_s_port_close_is_said_once_and_as_in_no_record(
    tmp_path: Path, close_fails: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Metering fails on a camera fault and its teardown closes the dome's port, which fails:
    kept with metering's teardown failures (it had been in none), said once by the dome's
    line, not as a teardown problem, and said to be in no session record, since none was
    written; the lights' line says what the all-off established."""
    import rti_rig.runtime.exposure_policy as exposure_policy
    from rti_rig.core.errors import DeviceError

    def camera_fails(*args: object, **kwargs: object) -> float:
        raise DeviceError("camera", "stopped answering (injected)", "capture")

    monkeypatch.setattr(exposure_policy, "metering_start_s", camera_fails)
    out = tmp_path / "S"
    code, text = _run_three(out, "--auto-exposure")
    assert code == 2, text
    assert "stopped answering (injected)" in text, text
    assert text.count(WORDS) == 1 and text.count(NO_RECORD) == 1, text
    assert "metering ended before the session began, so none was written" in text, text
    assert "teardown problem" not in text, text
    assert "All-off sent and acknowledged by the dome: lights are off; nothing was" in text, text
    assert not out.exists()  # no record made up for it


def test_a_port_close_of_a_run_stopped_before_it_began_is_said_as_in_no_record(
    tmp_path: Path, close_fails: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A SIGTERM as the capture checks the free space, the dome held open after metering: the
    session's close sends the all-off and closes the port, which fails. The run never began,
    so no manifest keeps it: that is said, and no folder is made for it."""
    import signal

    import rti_rig.runtime.controller as controller

    def check_free_space(*args: object, **kwargs: object) -> None:
        signal.raise_signal(signal.SIGTERM)

    monkeypatch.setattr(controller, "check_free_space", check_free_space)
    out = tmp_path / "S"
    code, text = _run_three(out, "--auto-exposure")
    assert code == 143, text
    assert text.count(WORDS) == 1 and text.count(NO_RECORD) == 1, text
    assert "this run had not begun, so it wrote none" in text, text
    assert "teardown problem" not in text, text
    assert not out.exists()


def test_metering_that_could_not_make_the_rig_safe_says_its_port_close_too(
    tmp_path: Path, close_fails: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Metering's all-off fails, then its close of the dome's port: the error had named the
    all-off alone, the port's failure carried nowhere (not said to be in no record), and the
    lights' line not pointed at the failure. Both are named, each once."""
    from rti_rig.runtime.lighting import DomeLighting

    real_safe = DomeLighting.safe
    calls: list[int] = []

    def safe(self: DomeLighting, emergency: bool = False) -> list[str]:
        calls.append(1)  # metering's is the first: its all-off never reaches the dome
        if len(calls) > 1:
            return real_safe(self, emergency)
        return ["all LEDs off: no reply (injected)"]

    monkeypatch.setattr(DomeLighting, "safe", safe)
    out = tmp_path / "S"
    code, text = _run_three(out, "--auto-exposure")
    assert code == 2, text
    assert "metering could not make the rig safe (all LEDs off: no reply (injected))" in text
    assert "and its lights' port did not close cleanly (said above)" in text, text
    assert text.count("all LEDs off: no reply (injected)") == 1, text
    assert text.count(WORDS) == 1 and text.count(NO_RECORD) == 1, text
    assert "teardown problem" not in text, text  # named in the error, not again
    assert not out.exists()
