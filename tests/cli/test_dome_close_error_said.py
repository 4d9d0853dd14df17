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
