"""``rti-rig probe`` of a port that is not there names the ports present as probe commands.

Why: its error ended "If the device came back under another name, set that port in the rig
config", but probe is given a port, not a config. The board here is the shipped emulated
dome's firmware on a pty, listed by the system (pyserial's ``comports`` and udev's by-id
folder, the part of the world faked) under a stable by-id name that links to that pty, so the
command printed, pasted into bash, probes the board.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
from conftest import ASCII_LOCALE_ENV, CONFIGS, emulated_dome_as_hardware, said
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.core.clock import SystemClock
from rti_rig.drivers import ports_present
from rti_rig.simulator.dome_firmware import emulated_dome_on_pty, firmware_for

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

#: The name the board had (no such file here) and its stable by-id name now.
GONE = "/dev/ttyACM-rti-rig-test-0"
BY_ID = "usb-Arduino_Mega_2560_85735313-if00"


def test_probe_of_a_missing_port_offers_the_probe_of_the_port_present(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "example_dome_48.lp").write_bytes((CONFIGS / "example_dome_48.lp").read_bytes())
    config = emulated_dome_as_hardware(tmp_path, "emulated_dome.toml", GONE)
    settings = load_rig_config(config).config.dome.serial
    firmware = firmware_for(settings, led_count=48, clock=SystemClock())
    with emulated_dome_on_pty(firmware) as link:
        by_id = tmp_path / "by id"  # a space: the name printed must paste as one word
        by_id.mkdir()
        (by_id / BY_ID).symlink_to(link.port)
        monkeypatch.setattr(ports_present, "BY_ID", by_id)
        board = SimpleNamespace(device=link.port, description="Arduino Mega", serial_number="")
        from serial.tools import list_ports

        monkeypatch.setattr(list_ports, "comports", lambda: [board])
        r = CliRunner().invoke(app, ["probe", GONE], terminal_width=400)
        words = said(r)
        assert r.exit_code != 0 and "Traceback" not in words, words
        assert "rig config" not in words, words
        before = "If the device came back under another name, give it to the command again: "
        assert before in words, words
        command = words.split(before, 1)[1].split(" (", 1)[0].strip()
        assert command.startswith("rti-rig probe "), command
        pasted = subprocess.run(
            ["bash", "-c", command.replace("rti-rig", '"$PY" -m rti_rig', 1)],
            capture_output=True,
            text=True,
            env={**ASCII_LOCALE_ENV, "PY": sys.executable, "COLUMNS": "400"},
            timeout=600,
        )
    out = " ".join((pasted.stdout + pasted.stderr).split())
    assert pasted.returncode == 0, out
    assert "Found: default." in out, out
