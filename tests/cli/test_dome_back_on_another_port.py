"""A dome that drops off the USB bus mid-session and comes back under another port name.

In the field (a laptop on battery, a USB hub) the dome's board vanishes and is enumerated again
as ``/dev/ttyACM1`` while the config still names ``/dev/ttyACM0``. What the user must see: the
run stops with the images so far kept and listed, no claim that the lights are off, and an
error that names the serial ports present now (with the stable ``/dev/serial/by-id/`` name);
a resume on the old config says the same, and ``rti-rig run FIXED.toml --resume DIR`` with the
port corrected finishes the session (a port's name is not the rig's identity). Before, the
error said only "No such file or directory", at the run and at each resume.

The shipped folder-watch dome (its framed board emulated on a pty, the camera a thread saving a
TIFF per shutter pulse); the system's port listing (pyserial's ``comports``, and udev's by-id
folder) is the part of the world faked: the emulator's pty is no USB device.
"""

from __future__ import annotations

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import serial
import tifffile
from conftest import Tether, folder_watch_config
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.clock import SystemClock
from rti_rig.drivers import ports_present
from rti_rig.simulator.dome_firmware import (
    Fault,
    FaultKind,
    FaultPlan,
    emulated_dome_on_pty,
    firmware_for,
)

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: The names the kernel gave the board before and after it dropped off (no such files here).
OLD, NEW = "/dev/ttyACM-rti-rig-test-0", "/dev/ttyACM-rti-rig-test-1"
BY_ID = "usb-Arduino_Mega_2560_85735313-if00"
LIGHTS = 4
#: The framed board's commands: three at the connect, then per light 'light', 'shutter pulse',
#: 'all off'; the 10th is the third light's, between steps with no LED lit (two shutter
#: pulses before it, checked below).
DROP_AT = 10


def _tiff(scratch: Path) -> bytes:
    tifffile.imwrite(scratch, np.full((32, 32, 3), 20000, np.uint16), photometric="rgb")
    data = scratch.read_bytes()
    scratch.unlink()
    return data


def _config(tmp_path: Path, tether: Path, port: str, name: str) -> Path:
    """The shipped folder-watch config on ``port``, its reconnection window short (0.7 s)."""
    cfg = folder_watch_config(tmp_path, tether, timeout_s=20.0, tiffs=True)
    text = cfg.read_text(encoding="utf-8")
    old = 'port = "/dev/serial/by-id/usb-Arduino_Mega_2560-if00"'
    assert old in text
    text = text.replace(old, f'port = "{port}"\nreconnect_backoff_s = 0.1')
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def system_ports(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The system lists the board as NEW, with its by-id link, as udev does after a replug."""
    by_id = tmp_path / "by-id"
    by_id.mkdir()
    (by_id / BY_ID).symlink_to(NEW)
    monkeypatch.setattr(ports_present, "BY_ID", by_id)
    board = SimpleNamespace(device=NEW, description="Arduino Mega 2560", serial_number="85735313")
    from serial.tools import list_ports

    monkeypatch.setattr(list_ports, "comports", lambda: [board])


def _run(args: list[str]) -> tuple[int, str]:
    r = CliRunner().invoke(app, [*args, "--no-verdict"], terminal_width=400)
    return r.exit_code, " ".join(r.output.split())


def _images(out: Path) -> list[str]:
    lines = (out / "lights.lp").read_text(encoding="utf-8").splitlines()[1:]
    return [line.split()[0] for line in lines if line.strip()]


@pytest.mark.slow  # three runs over a pty, a reconnection window of 0.7 s: about 9 s
def test_a_dome_back_under_another_name_is_named_and_the_session_resumes_on_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, system_ports: None
) -> None:
    tether = tmp_path / "tether"
    tether.mkdir()
    old_cfg = _config(tmp_path, tether, OLD, "rig.toml")
    new_cfg = _config(tmp_path, tether, NEW, "rig-acm1.toml")
    out = tmp_path / "s"
    data = _tiff(tmp_path / "scratch.tif")
    routes = {OLD: str(tmp_path / "gone")}  # a device path that no longer exists
    real = serial.serial_for_url

    def redirect(url, *args, **kwargs):  # type: ignore[no-untyped-def]
        return real(routes.get(url, url), *args, **kwargs)

    monkeypatch.setattr(serial, "serial_for_url", redirect)
    settings = load_rig_config(old_cfg).config.dome.serial  # type: ignore[union-attr]

    def served(port: str, faults: FaultPlan, names: list[str]):  # type: ignore[no-untyped-def]
        firmware = firmware_for(settings, led_count=48, clock=SystemClock(), faults=faults)
        files = [(n, data) for n in names]
        return firmware, emulated_dome_on_pty(firmware), Tether(firmware, tether, files)

    # the run: the board drops off for good after its second image
    drop = FaultPlan.of(Fault(DROP_AT, FaultKind.DISCONNECT, delay_s=60.0))
    firmware, serving, camera = served(OLD, drop, [f"A_{n}.tif" for n in range(LIGHTS)])
    with serving as link:
        routes[OLD] = link.port
        camera.start()
        try:
            code, said = _run(["run", str(old_cfg), "--out", str(out), "--lights", str(LIGHTS)])
        finally:
            camera.stop.set()
            camera.join(5.0)
        shots = sum(e.what == "shutter" for e in firmware.history)
    routes[OLD] = str(tmp_path / "gone")
    assert code == 2, said
    assert shots == 2, said  # the drop came after the second image, as DROP_AT means
    kept = _images(out)
    assert len(kept) == 2, said
    assert all((out / k).is_file() for k in kept), kept
    assert f"cannot open serial port {OLD}: No such file or directory" in said, said
    assert f"serial ports present now: {NEW} (Arduino Mega 2560, serial number 85735313, " in said
    assert f"by-id/{BY_ID})" in said, said
    # the teardown's line shortens the error to its first clause, its parentheses closed
    teardown = said[said.index("teardown problem:") : said.index("(as in the error below)")]
    assert teardown.count("(") == teardown.count(")"), teardown
    assert "the /dev/serial/by-id/ name stays the same" in said, said
    assert "lights are off" not in said, said
    assert f"rti-rig run --resume {out}" in said, said

    # the board is back as NEW: a resume on the session's own config names it, loses nothing
    code, said = _run(["run", "--resume", str(out)])
    assert code == 2, said
    assert f"serial ports present now: {NEW} (" in said, said
    # said once, in the error: the lights line had repeated the whole listing beside it
    assert said.count("serial ports present now") == 1, said
    assert "the error says which serial ports are present now" in said, said
    assert _images(out) == kept

    # the config pointed at NEW: the session goes on where it stopped and completes
    firmware, serving, camera = served(NEW, FaultPlan(), [f"B_{n}.tif" for n in range(LIGHTS)])
    with serving as link:
        routes[NEW] = link.port
        camera.start()
        try:
            code, said = _run(["run", str(new_cfg), "--resume", str(out)])
        finally:
            camera.stop.set()
            camera.join(5.0)
        shots = sum(e.what == "shutter" for e in firmware.history)
    assert code == 0, said
    assert shots == LIGHTS - len(kept), said
    images = _images(out)
    assert len(images) == LIGHTS and images[: len(kept)] == kept, images
    assert "All-off sent and acknowledged by the dome: lights are off." in said, said


def test_a_port_outside_dev_gets_no_listing() -> None:
    """An emulator's pty or a URL is no device a user points a config at: no listing."""
    assert ports_present.ports_present_note("/tmp/rti-rig-pty-x/tty-dome") == ""
    assert ports_present.ports_present_note("loop://") == ""


def test_a_listing_that_fails_is_said_in_the_systems_words(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The port listing refused (sysfs not readable) is named as the system says it, not as
    Python's text of the error (``[Errno 13] Permission denied: '/sys/class/tty'``); a by-id
    folder that cannot be read only loses the stable names, not the listing."""
    from serial.tools import list_ports

    def refused() -> list[object]:
        raise PermissionError(13, "Permission denied", "/sys/class/tty")

    monkeypatch.setattr(list_ports, "comports", refused)
    note = ports_present.ports_present_note("/dev/ttyACM0")
    assert note == "the serial ports present could not be listed (Permission denied)", note

    board = SimpleNamespace(device="/dev/ttyACM1", description="n/a", serial_number=None)
    monkeypatch.setattr(list_ports, "comports", lambda: [board])
    monkeypatch.setattr(ports_present, "BY_ID", tmp_path / "not-a-folder")
    (tmp_path / "not-a-folder").write_text("", encoding="utf-8")
    note = ports_present.ports_present_note("/dev/ttyACM0")
    assert note.startswith("serial ports present now: /dev/ttyACM1. If the device came"), note
