"""An emulated dome or arm config with a real port set is refused, naming the key and what to set.

The shipped ``emulated_*.toml`` of the real firmwares said "Only [dome.serial] differs on the
real dome: set port". A user who did so kept ``backend = "emulated"``: the dry run served its
own emulator, never opened the port, and ``rti-rig check`` said PASS of a dome it never reached.
The emulated arm (``simulated_arm.toml``: "on hardware e.g. /dev/ttyUSB0 (U2D2)") did the same:
a full arm check PASS against the emulated servos, the U2D2's port never opened.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.mark.parametrize(
    ("name", "key", "port"),
    [
        ("emulated_nab_rti_v1.toml", "[dome.serial]", "/dev/ttyACM0"),
        ("emulated_dome.toml", "[dome.serial]", "/dev/ttyACM0"),
        ("simulated_arm.toml", "[arm.dynamixel]", "/dev/ttyUSB0"),
    ],
)
def test_a_real_port_under_the_emulated_backend_is_refused(
    tmp_path: Path, name: str, key: str, port: str
) -> None:
    text = (CONFIGS / name).read_text()
    assert 'port = "emulated"' in text and 'backend = "emulated"' in text
    cfg = tmp_path / "rig.toml"
    cfg.write_text(text.replace('port = "emulated"', f'port = "{port}"', 1))
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"{key} port = '{port}' with backend = 'emulated'" in said, said
    assert "never opens that port" in said and "set backend = 'hardware'" in said
    assert "RESULT" not in said and "Traceback" not in said


def test_the_shipped_headers_say_what_the_real_dome_needs() -> None:
    for cfg in CONFIGS.glob("emulated_*.toml"):
        text = cfg.read_text()
        assert "Only [dome.serial] differs" not in text, cfg.name
