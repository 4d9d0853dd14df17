"""A tethered DSLR that drops off mid-session and comes back on another USB device number.

libgphoto2's ``usb:BUS,DEVICE`` changes at every plugging: a config that sets ``port`` (to
choose between bodies) names a port the camera is no longer on once it is back. The resume had
been refused with "no camera on port usb:001,004; found [('Canon EOS 600D', 'usb:001,005')]":
a Python list, and nothing of why or what to do. It now names the camera found, why its port
changed and the line to set; with it set, the resume shoots the rest (a port is not the rig's
identity). Through ``rti-rig run`` on the shipped DSLR example (its dome emulated on a pty,
python-gphoto2 replaced at its API boundary by tests/fake_gphoto2.py).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import shipped_dome_on_pty
from fake_gphoto2 import Body, make_module
from test_dslr_download_disk_full import _config, _raw  # the same shipped DSLR, small
from typer.testing import CliRunner

from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


def _run(monkeypatch: pytest.MonkeyPatch, cfg: Path, argv: list[str]) -> tuple[int, str, object]:
    with shipped_dome_on_pty(monkeypatch, cfg) as firmware:
        r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
        lit = firmware.lit
    return r.exit_code, " ".join(r.output.split()), lit


def test_a_dslr_back_on_another_usb_number_is_named_and_the_resume_goes_on(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shipped = _config(tmp_path, "Memory card")
    text = shipped.read_text()
    cfg = tmp_path / "dslr-port.toml"
    cfg.write_text(text.replace("[camera.device]\n", '[camera.device]\nport = "usb:001,004"\n'))
    body = Body(render=_raw, port="usb:001,004", off_at_call=("capture", 3))
    monkeypatch.setitem(sys.modules, "gphoto2", make_module(body))
    out = tmp_path / "s"
    code, said, lit = _run(monkeypatch, cfg, ["run", str(cfg), "--out", str(out), "--lights", "4"])
    assert code == 2 and lit is None, said
    assert "rti-rig run --resume" in said and "Traceback" not in said, said
    assert (out / "lights.lp").read_text().split()[0] == "2"

    body.port = "usb:001,005"  # plugged back in: the system numbers the device anew
    body.switch_on()
    code, said, lit = _run(monkeypatch, cfg, ["run", "--resume", str(out)])
    assert code == 2 and lit is None, said
    assert "no camera on port usb:001,004 (a usb: port is the USB device number" in said, said
    assert "cameras found now: Canon EOS 600D on usb:001,005." in said, said
    assert 'set port = "usb:001,005" in [camera.device]' in said, said
    assert "[(" not in said, said
    assert (out / "lights.lp").read_text().split()[0] == "2"

    cfg.write_text(cfg.read_text().replace("usb:001,004", "usb:001,005"))
    code, said, lit = _run(monkeypatch, cfg, ["run", str(cfg), "--resume", str(out)])
    assert code == 0, said
    assert (out / "lights.lp").read_text().split()[0] == "4"
    assert sorted(p.name for p in (out / "raw").glob("*.cr2")) == [
        f"image_{k:03d}.cr2" for k in range(1, 5)
    ]
