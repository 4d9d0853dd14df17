"""`rti-rig run --auto-exposure` keeps the dome's port open from metering to the session.

The Nab "RTI v1.0" sketch boots with every LED lit (``setup()`` calls ``lightsOn()``) and its
Uno-class board resets each time its port opens. Metering had closed the port and the session
opened it again: the board rebooted and lit the whole dome a second time until the session's
all-off (0.77 s of full light in all on this config, against 0.39 s), a dose the object need
not take, and one more boot wait. The emulator's timeline is the truth: the dome is wholly lit
once (the first opening), and dark at the end with the lights line as established.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.compose as compose
from rti_rig.cli import app

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.slow,  # the emulated board runs in real time
    pytest.mark.pty,
    pytest.mark.e2e,
]
runner = CliRunner()


def test_metering_then_session_boots_the_nab_board_lit_only_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    boards: list = []  # type: ignore[type-arg]
    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        boards.append(rig.emulator)
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    config = CONFIGS / "emulated_nab_rti_v1.toml"
    out = tmp_path / "s"
    result = runner.invoke(
        app, ["run", str(config), "--auto-exposure", "--lights", "2", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    assert "Exposure fixed at" in result.output
    assert "acknowledged by the dome: lights are off" in result.output
    (board,) = boards
    # every boot lights all the wired LEDs at once; a single light is one LED
    boots_lit = [leds for _, leds in board.timeline if len(leds) > 1]
    assert len(boots_lit) == 1, f"the dome was wholly lit {len(boots_lit)} times"
    assert board.lit_once_booted() == frozenset()
    assert len(list(out.glob("image_*.jpg"))) == 2
