"""``rti-rig probe`` given a path that is no serial port, and the case of its error line.

A regular file, a folder or ``/dev/null`` given as the port had been told to check that the
dome is plugged in and powered: the path was the mistake, and the probe now says what the path
is. Its error line read "ERROR:" where every other command says "error:".
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from conftest import said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def _path(kind: str, folder: Path) -> Path:
    if kind == "file":
        (folder / "rig.toml").write_text('name = "a config, not a port"\n')
        return folder / "rig.toml"
    return folder if kind == "folder" else Path(kind)


@pytest.mark.parametrize(
    ("kind", "what"),
    [
        ("file", "is a regular file"),
        ("folder", "is a folder"),
        ("/dev/null", "is a device but not a terminal"),
        # its open fails with EINVAL, not ENOTTY: it had been told to check the dome's cable
        ("/dev/random", "is a device but not a terminal"),
    ],
)
def test_a_path_that_is_no_serial_port_is_named_as_such(
    tmp_path: Path, kind: str, what: str
) -> None:
    port = _path(kind, tmp_path)
    r = runner.invoke(app, ["probe", str(port)])
    text = said(r)
    assert r.exit_code == 1, text
    assert f"{port} {what}: it is not a serial port, so no firmware was asked" in text, text
    assert "plugged in" not in text and "profile =" not in text, text
    assert "error: cannot open serial port" in text and "ERROR" not in text, text


def test_a_missing_port_keeps_the_advice_to_check_its_name_and_the_dome(tmp_path: Path) -> None:
    r = runner.invoke(app, ["probe", str(tmp_path / "ttyACM9")])
    text = said(r)
    assert r.exit_code == 1, text
    assert "error: cannot open serial port" in text and "ERROR" not in text, text
    assert "that the dome is plugged in and powered" in text, text
    assert "is not a serial port" not in text, text


def test_the_error_goes_to_stderr_on_one_line(tmp_path: Path) -> None:
    """Every other command says its error on stderr; probe's went to stdout, and wrapped mid-
    message in a pipe (a long port path makes it longer than the 80 columns of a pipe)."""
    port = tmp_path / ("a-long-folder-name-for-a-port-" * 3) / "ttyACM9"
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", "probe", str(port)],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=Path(__file__).resolve().parents[2],
    )
    assert r.returncode == 1, r.stdout + r.stderr
    assert "error:" not in r.stdout, r.stdout
    line = next(line for line in r.stderr.splitlines() if line.startswith("error:"))
    assert line.startswith(f"error: cannot open serial port {port}: "), r.stderr
    assert line.rstrip().endswith("No such file or directory"), r.stderr
    assert "Traceback" not in r.stderr, r.stderr


@pytest.mark.parametrize("device", ["/dev/null", "/dev/random"])
def test_a_device_that_is_no_terminal_is_named_whatever_pyserial_words_its_failure(
    monkeypatch: pytest.MonkeyPatch, device: str
) -> None:
    """The probe decides from the system's number for the failure (ENOTTY, EINVAL, carried by
    the transport's error), not from the words of pyserial's message: it had looked for
    "Inappropriate ioctl" and "Could not configure port" in the text, so a pyserial that words
    it otherwise sent the user to check the dome's cable. Here pyserial's open is replaced by
    one that does what it does (open the device, read its terminal settings, which the system
    refuses) and says so in other words."""
    import os
    import termios

    import serial

    def open_with_other_words(port: str, **_: object) -> None:
        fd = os.open(port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        try:
            termios.tcgetattr(fd)  # the system's refusal, with its own number
        except termios.error:
            raise serial.SerialException(f"port {port} refused its terminal settings") from None
        finally:
            os.close(fd)
        raise AssertionError(f"{port} accepted a terminal's settings")

    monkeypatch.setattr(serial, "serial_for_url", open_with_other_words)
    r = runner.invoke(app, ["probe", device])
    text = said(r)
    assert r.exit_code == 1, text
    assert f"{device} is a device but not a terminal: it is not a serial port" in text, text
    assert "plugged in" not in text and "Traceback" not in text, text


class _UnpluggedAfterOpening:
    """A pty standing for a USB serial adapter pulled out just after the port is opened: its
    other end is closed once pyserial's opening returns, so the first read meets the system's
    EIO, as an unplugged adapter's does."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        import os
        import pty

        import serial

        self.master, slave = pty.openpty()
        self.port = os.ttyname(slave)
        os.close(slave)
        self.open = True
        real = serial.serial_for_url

        def opens_then_unplugged(url: str, **kwargs: object) -> object:
            opened = real(url, **kwargs)
            self.unplug()
            return opened

        monkeypatch.setattr(serial, "serial_for_url", opens_then_unplugged)

    def unplug(self) -> None:
        import os

        if self.open:
            os.close(self.master)
            self.open = False


@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_a_port_that_opens_then_fails_is_not_said_to_have_failed_to_open(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A serial port that opens and then fails on its first read (a USB adapter pulled out
    just after, another program taking the port): the conclusion had said "The port could
    not be opened", under an error line saying the read failed, and had looked up what the
    path is from the read's failure. It is decided now on the typed error's kind."""
    adapter = _UnpluggedAfterOpening(monkeypatch)
    try:
        r = runner.invoke(app, ["probe", adapter.port])
    finally:
        adapter.unplug()
    text = said(r)
    assert r.exit_code == 1, text
    assert f"error: read from {adapter.port} failed" in text, text
    assert "The port opened but failed before any firmware answered" in text, text
    assert "could not be opened" not in text and "not a serial port" not in text, text
    # the opening reset the board all the same (the Nab sketch boots with every LED on): the
    # lights had been "the port could not be used; nothing was sent"
    assert (
        "Lights: the port failed once open, before a firmware answered: nothing that lights "
        "an LED was sent, but opening the port resets a board like an Arduino"
    ) in text, text
    assert "nothing was sent" not in text, text
    assert "Traceback" not in text, text

    from rti_rig.app.usecases.probe import LightsState, ProbeFailure, ProbeRequest, probe

    adapter = _UnpluggedAfterOpening(monkeypatch)
    try:
        result = probe(ProbeRequest(adapter.port, listen_s=0.3))
    finally:
        adapter.unplug()
    assert result.error is not None and result.error.failure is ProbeFailure.PORT_FAILED
    assert result.lights_state is LightsState.PORT_FAILED_UNANSWERED
    assert "look at the dome" in result.lights
