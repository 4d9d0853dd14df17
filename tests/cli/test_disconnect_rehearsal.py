"""The documented USB-drop rehearsal recovers on the shipped emulated firmware configs.

docs/domes.md tells a user to rehearse a USB drop with ``--fault K:disconnect`` (the port gone
for 1 s). The shipped ``emulated_*.toml`` gave the dome 2 reconnection attempts from 0.2 s, 0.6 s
in all, so the rehearsal always ended "did not come back within 2 reconnection attempts over
0.6 s" — and a user who copied the config to the real dome (its comment says only the port
differs) kept a window shorter than the 0.1–2 s Linux waits for a replugged port to settle.
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from rti_rig.app.config import load_rig_config
from rti_rig.cli import app
from rti_rig.simulator.dome_firmware import Fault, FaultKind


def _serial(name: str):  # type: ignore[no-untyped-def]
    dome = load_rig_config(CONFIGS / name).config.dome
    return None if dome is None else dome.serial


#: The shipped dry runs of the real firmwares, over a pty (the configs a user copies).
FIRMWARE_CONFIGS = sorted(
    p.name
    for p in CONFIGS.glob("emulated_*.toml")
    if (s := _serial(p.name)) is not None and s.is_described
)
#: Linux's hub driver waits up to 2 s for a replugged port's connection to be stable
#: (``HUB_DEBOUNCE_TIMEOUT`` in drivers/usb/core/hub.c) before it enumerates the device.
USB_SETTLE_S = 2.0


def test_every_real_firmware_has_a_shipped_config() -> None:
    assert len(FIRMWARE_CONFIGS) == 6, FIRMWARE_CONFIGS


@pytest.mark.parametrize("name", FIRMWARE_CONFIGS)
def test_the_shipped_reconnect_window_outlasts_a_replug_and_the_rehearsed_drop(name: str) -> None:
    serial = _serial(name)
    backoffs = [serial.reconnect_backoff_s * 2**k for k in range(serial.reconnect_attempts)]
    assert sum(backoffs) >= 2 * USB_SETTLE_S, (name, backoffs)
    # the rehearsal's drop ends between two attempts, with room on both sides (not on one)
    drop = Fault(1, FaultKind.DISCONNECT).delay_s
    ends = [sum(backoffs[: k + 1]) for k in range(len(backoffs))]
    assert any(a <= drop - 0.3 and b >= drop + 0.3 for a, b in itertools.pairwise(ends)), ends


@pytest.mark.slow  # real firmware timing over a pty, and one USB drop of 1 s
@pytest.mark.pty
@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_the_documented_disconnect_rehearsal_recovers(tmp_path: Path) -> None:
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
        + '\n[[emulator.faults]]\nat_command = 5\nkind = "disconnect"\n'
    )
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "did not come back" not in said
    assert "1 reconnects" in said, said
    assert "LEDs stepped: 12, acknowledged by the board: 12, failed: 0" in said, said
    assert "all-off sent and acknowledged by the dome: lights are off" in said, said
    assert "RESULT: PASS" in said, said
