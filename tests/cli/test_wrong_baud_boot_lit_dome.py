"""A Nab board that the connect's all-off did not reach is said to be fully lit, if it is one.

The Nab sketch lights every LED in ``setup()``, and its Uno-class board resets when the port
opens. At a wrong ``baudrate`` (115200 left from the example config) nothing the host sends
reaches the sketch: the check's lights line said "lights may still be on; check the dome" of
a dome the opening had just lit whole. It now says that this firmware lights every LED at
boot, that opening the port resets the board, and to switch the dome off at its supply. The
emulator's record is the truth: every LED is lit at the end.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.compose as compose
import rti_rig.app.usecases.check as check_usecase
from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.slow,  # the emulated board boots and is waited for in real time
    pytest.mark.pty,
]


def test_a_nab_board_at_a_wrong_baud_rate_is_said_to_be_lit_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    boards: list = []  # type: ignore[type-arg]
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        boards.append(rig.emulator)
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    monkeypatch.setattr(check_usecase, "build_rig", build)
    text = (CONFIGS / "emulated_nab_rti_v1.toml").read_text()
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        text.replace('profile = "nab-rti-v1"', 'profile = "nab-rti-v1"\nbaudrate = 115200')
    )
    r = CliRunner().invoke(app, ["check", str(cfg)], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1, said
    assert "the nab-rti-v1 firmware lights every LED as its board boots" in said, said
    assert "switch the dome off at its power supply" in said
    (board,) = boards
    assert len(board.lit) > 1  # the truth: the board is lit whole
