"""An arm whose USB adapter came back under another port name is told the ports present.

The arm's U2D2 dropped off a hub and came back as ``/dev/ttyUSB1``; the config still names
``/dev/ttyUSB0``. The open had said pyserial's "No such file or directory" and to check the
adapter is plugged in (it is). It now names the serial ports present, with their stable
``/dev/serial/by-id/`` names (drivers/ports_present.py says why rti-rig does not move to one by
itself). The system's port listing is what is faked; the refusal comes before any servo moves.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers import ports_present

OLD, NEW = "/dev/ttyUSB-rti-rig-test-0", "/dev/ttyUSB-rti-rig-test-1"
BY_ID = "usb-FTDI_USB__-__Serial_Converter_FT4TFSV1-if00-port0"


def test_an_arm_port_gone_names_the_ports_present(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    by_id = tmp_path / "by-id"
    by_id.mkdir()
    (by_id / BY_ID).symlink_to(NEW)
    monkeypatch.setattr(ports_present, "BY_ID", by_id)
    u2d2 = SimpleNamespace(device=NEW, description="USB <-> Serial Converter", serial_number=None)
    from serial.tools import list_ports

    monkeypatch.setattr(list_ports, "comports", lambda: [u2d2])
    text = (CONFIGS / "simulated_arm.toml").read_text(encoding="utf-8")
    for old, new in (
        ('backend = "emulated"', 'backend = "hardware"'),
        ('port = "emulated"', f'port = "{OLD}"'),
    ):
        assert old in text, old
        text = text.replace(old, new)
    tether = tmp_path / "tether"
    tether.mkdir()
    text = text[: text.index("[scene]")]
    text += f'[camera.device]\nkind = "folder_watch"\nfolder = "{tether}"\n'
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text, encoding="utf-8")
    out = tmp_path / "s"
    argv = ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"cannot open port '{OLD}': No such file or directory; serial ports" in said, said
    assert "[Errno" not in said, said  # the system's reason, not pyserial's Python text
    assert f"serial ports present now: {NEW} (USB <-> Serial Converter, {by_id}/{BY_ID})" in said
    assert f"({OLD} is a name the system gives at each plugging;" in said, said
    assert "Nothing was commanded: the arm could not be connected." in said, said
    assert "Traceback" not in said
