"""A fault no part of rti-rig named, while ``run --auto-exposure`` meters, is said with what
metering's teardown established of the lights, as an error it named is.

A camera driver's TypeError in metering's first test shot made the run say "metering, if it
had begun, attempted an all-off on its way out: check the rig's lights" of an emulated dome
that had been sent the all-off and had acknowledged it: what was established went unsaid. The
emulated dome's firmware (its received commands read as the other CLI tests read them) and the
real driver, through ``run``; only the camera's capture is made to fail."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

import rti_rig.simulator.sim_camera as sim_camera
from rti_rig.cli import app
from rti_rig.simulator.dome_firmware import DomeFirmware
from rti_rig.simulator.own_protocols import Verb


def test_an_unnamed_fault_while_metering_says_the_all_off_the_dome_acknowledged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    received: list[str] = []
    real_execute = DomeFirmware._execute

    def execute(self, req, now):  # type: ignore[no-untyped-def]
        received.append(req.verb)
        return real_execute(self, req, now)

    def capture(self: object, exposure_s: float) -> object:
        raise TypeError("a driver's own bug")

    monkeypatch.setattr(DomeFirmware, "_execute", execute)
    monkeypatch.setattr(sim_camera.SimulatedCamera, "capture", capture)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--auto-exposure"], terminal_width=400)
    text = said(r)
    assert Verb.LIGHT in received, (received, text)  # metering lit the dome
    assert received[-1] == Verb.ALL_OFF, (received, text)  # and its teardown switched it off
    assert (
        "metering failed, and then: all-off sent and acknowledged by the dome: lights are off"
        in text.lower()
    ), text
    assert "check the rig's lights" not in text, text
    assert "unexpected TypeError: a driver's own bug" in text, text
    assert "Traceback" not in text, text
    assert r.exit_code == 1, text
    assert not any(out.glob("image_*"))
