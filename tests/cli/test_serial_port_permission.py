"""A serial port that exists but that this user may not open (EACCES), on the arm and the dome.

The arm had said pyserial's raw text ("[Errno 13] could not open port P: [Errno 13] Permission
denied: 'P'") and then "check that the arm's USB adapter is plugged in", which it was; the dome
"Permission denied" alone. Both now name the port, say it is a permission problem and what to
do on Linux (join the device's group, then log in again), in the same words
(:func:`rti_rig.drivers.serial_ports.permission_denied_why`). The refusal is raised where
pyserial raises it (its ``SerialException`` carrying errno 13): the tests run as any user.
"""

from __future__ import annotations

import errno
import grp
import os
import sys
from pathlib import Path

import pytest
import serial
from conftest import CONFIGS, emulated_dome_as_hardware, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.serial_ports import permission_denied_why
from rti_rig.simulator import dynamixel_pty

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")

#: what both devices say of the refusal, after the port's name
ADVICE = "permission denied: this user may not open it; on Linux, add the user to the '"
RELOGIN = "then log out and in again (a new group counts only from the next login)"


def _refused(port: str) -> serial.SerialException:
    """pyserial's exception for an open the system refused with EACCES."""
    return serial.SerialException(
        errno.EACCES, f"could not open port {port}: [Errno 13] Permission denied: '{port}'"
    )


def _said_refused(monkeypatch: pytest.MonkeyPatch, *args: str) -> str:
    """What ``rti-rig ARGS`` says where the system refuses every serial port pyserial opens
    (EACCES, raised where pyserial raises it), its exit status 1 checked."""

    def serial_for_url(url, *args, **kwargs):  # type: ignore[no-untyped-def]
        raise _refused(url)

    monkeypatch.setattr(serial, "serial_for_url", serial_for_url)
    r = CliRunner().invoke(app, list(args))
    text = said(r)
    assert r.exit_code == 1, text
    return text


def test_an_arm_port_not_this_user_s_to_open_is_said_so(monkeypatch: pytest.MonkeyPatch) -> None:
    def open_port(self):  # type: ignore[no-untyped-def]
        raise _refused(self.port_name)

    monkeypatch.setattr(dynamixel_pty.EmulatedLinkPortHandler, "openPort", open_port)
    r = CliRunner().invoke(app, ["check", str(CONFIGS / "simulated_arm.toml")])
    text = said(r)
    assert r.exit_code == 1, text
    assert "ABORTED: arm during 'open': cannot open port '" in text, text
    assert f"': {ADVICE}" in text and RELOGIN in text, text
    # neither pyserial's raw words nor the advice for an adapter that is not there
    assert "Errno" not in text and "plugged in" not in text, text
    assert "Traceback" not in text, text


def test_a_dome_port_not_this_user_s_to_open_is_said_in_the_same_words(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    port = tmp_path / "ttyACM0"
    port.write_text("")
    text = _said_refused(monkeypatch, "probe", str(port))
    assert f"error: cannot open serial port {port}: {ADVICE}" in text, text
    assert RELOGIN in text and "Errno" not in text and "Traceback" not in text, text


def test_the_group_named_is_the_device_s_own(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Arch Linux's serial devices belong to ``uucp``, not ``dialout``; a device owned by the
    root group (or one gone) is told the usual ``dialout``, never "join root"."""
    port = tmp_path / "ttyUSB0"
    port.write_text("")
    gid = port.stat().st_gid

    def group_of(number: int) -> grp.struct_group:
        name = "uucp" if number == gid else "other"
        return grp.struct_group((name, "x", number, []))

    monkeypatch.setattr(grp, "getgrgid", group_of)
    assert "the 'uucp' group (sudo usermod -aG uucp $USER)" in permission_denied_why(str(port))
    monkeypatch.setattr(grp, "getgrgid", lambda n: grp.struct_group(("root", "x", n, [])))
    assert "the 'dialout' group" in permission_denied_why(str(port))
    assert "the 'dialout' group" in permission_denied_why(str(tmp_path / "gone"))


def test_a_dome_port_not_this_user_s_to_open_is_not_said_unplugged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A user's dome config through check, and probe on a device node: the refusal's advice
    stands alone, as the arm's does. The dome's check had gone on "check that the board is
    plugged in", and probe "Check ... that the dome is plugged in and powered", of a port
    that is there."""
    port = tmp_path / "ttyACM0"
    port.write_text("")
    cfg = emulated_dome_as_hardware(tmp_path, "emulated_nab_rti_v1.toml", str(port))
    text = _said_refused(monkeypatch, "check", str(cfg))
    opened = f"'open port': the dome's port could not be opened (cannot open serial port {port}: "
    assert opened + ADVICE in text, text
    assert ADVICE in text and RELOGIN in text, text
    assert "plugged in" not in text and "Traceback" not in text, text
    # a character device (no regular file, which probe says is no serial port)
    text = _said_refused(monkeypatch, "probe", os.devnull)
    assert f"error: cannot open serial port {os.devnull}: {ADVICE}" in text, text
    assert "The port is there but this user may not open it, so no firmware was asked" in text
    assert "plugged in" not in text and "Traceback" not in text, text
