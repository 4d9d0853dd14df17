"""The shared dome fixtures (tests/conftest.py) meet the firmware a config names.

``shipped_dome_on_pty`` had served every profile the codec-driven ``DomeFirmware``, which speaks
rti-rig's binary protocol for a firmware's profile: ``rti-rig probe`` through it on the RTIPy
dome said "Found: binary", and a test "on RTIPy" tested another board. And
``emulated_dome_as_hardware`` put its ``[camera.device]`` at the first ``[timing]`` of the text,
inside a comment of emulated_rtipy.toml: a file TOML refuses. Here each shipped serial firmware
is served through both, as a user's hardware copy of its dry run names it. (``rti-rig probe``
through the fixed fixture on the RTIPy copy says "Found: rtipy."; at about 20 s a probe is
left out of the suite.)
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

import pytest
from conftest import CONFIGS, emulated_dome_as_hardware, shipped_dome_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


#: the shipped dry runs of a real firmware's serial dome: their emulators are the fixture's
SHIPPED_FIRMWARES = {
    "emulated_nab_rti_v1.toml": "NabRtiV1Board",
    "emulated_rtipy.toml": "RtiPyBoard",
    "emulated_minirti.toml": "MiniRtiBoard",
    "emulated_elexol.toml": "ElexolBoard",
    "emulated_rti_dome.toml": "RtiDomeBoard",
    "emulated_nichlock.toml": "NichlockBoard",
}


@pytest.mark.parametrize("shipped", list(SHIPPED_FIRMWARES))
def test_the_hardware_copy_is_toml_and_its_port_serves_the_firmware_it_names(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, shipped: str
) -> None:
    import serial

    port = "/dev/ttyACM7"
    config = emulated_dome_as_hardware(tmp_path, shipped, port)
    data = tomllib.loads(config.read_text(encoding="utf-8"))  # a TOML file, as a user's is
    assert data["backend"] == "hardware" and data["dome"]["serial"]["port"] == port
    assert data["camera"]["device"] == {"kind": "folder_watch", "folder": str(tmp_path / "tether")}
    assert data["timing"] == tomllib.loads((CONFIGS / shipped).read_text())["timing"]
    with shipped_dome_on_pty(monkeypatch, config) as board:
        assert type(board).__name__ == SHIPPED_FIRMWARES[shipped], type(board)
        with serial.serial_for_url(port, baudrate=board.baudrate, timeout=0) as link:
            assert link.port != port  # the config's port opens the board's pty


def test_the_fixture_refuses_a_dome_it_has_no_serial_emulator_for(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The camera-stepped cceh/rti dome has no serial link: nothing is served in its place."""
    with (
        pytest.raises(ValueError, match=r"emulated_cceh_rti\.toml: no \[dome\.serial\]"),
        shipped_dome_on_pty(monkeypatch, CONFIGS / "emulated_cceh_rti.toml"),
    ):
        pass
