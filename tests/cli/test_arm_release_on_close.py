"""``rti-rig check`` on an arm whose ``torque_policy = "release_on_close"`` says that the park
pose is not held once its torque is released.

A limp elevation joint is back-driven by the lamp's weight (the emulator models it falling to
its lower limit at 10 °/s, an assumption: docs/protocols/dynamixel-arm.md; a real arm falls to
its mechanical stop, if it has one). The check had said "parked" and no more, of a pose the arm
then left. Whether the servos let go is read back: the torque-off is a broadcast, unanswered."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import emulators_built_by_check, inprocess_arm_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.drivers.dynamixel import control_table as ct

RELEASE = ('torque_policy = "hold"', 'torque_policy = "release_on_close"')


def _config(tmp_path: Path, park_elevation_deg: float | None = None) -> Path:
    cfg = inprocess_arm_config(tmp_path)
    text = cfg.read_text()
    assert RELEASE[0] in text
    text = text.replace(*RELEASE)
    if park_elevation_deg is not None:
        text = text.replace(
            "park_elevation_deg = 10.0", f"park_elevation_deg = {park_elevation_deg}"
        )
    cfg.write_text(text)
    return cfg


def test_a_released_park_above_the_lower_limit_is_said_not_to_be_held(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    emulators = emulators_built_by_check(monkeypatch)
    r = CliRunner().invoke(app, ["check", str(_config(tmp_path))], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert (
        "parked (read back at az 0.0°, el 10.0°, within 1° of its park pose); torque then "
        'released (torque_policy = "release_on_close", read back off on each servo)' in said
    ), said
    assert "may lower the elevation joint from its park pose (10°), past its lower limit" in said
    assert 'set torque_policy = "hold"' in said
    (emu,) = emulators  # the truth: the torque really is off, so the pose is not held
    assert all(s.get(ct.TORQUE_ENABLE) == 0 for s in emu.servos.values())


def test_a_released_park_at_the_lower_limit_is_not_said_to_rest_there(
    tmp_path: Path,
) -> None:
    """min_deg is a software limit: a limp joint does not keep it, and falls to the arm's
    mechanical stop, if it has one. The check had said the lamp "rests at its lower limit",
    and advised parking there, from the emulator (whose lamp stops falling at min_deg)."""
    r = CliRunner().invoke(
        app, ["check", str(_config(tmp_path, park_elevation_deg=0.0))], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "torque then released" in said, said
    assert "rests" not in said and "park_elevation_deg" not in said, said
    assert "past its lower limit (min_deg = 0°, a software limit" in said, said
    assert "until the arm meets a mechanical stop" in said, said


def test_a_torque_off_that_did_not_reach_the_servos_is_not_called_released(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The torque-off is a broadcast write, which no servo answers: lost on the bus (a
    corrupted packet, which a servo discards), it left both servos holding while the check said
    "torque then released … the joints are limp". Torque Enable is now read back."""
    from rti_rig.drivers.dynamixel.bus import DxlBus

    emulators = emulators_built_by_check(monkeypatch)
    real_broadcast = DxlBus.broadcast_write

    def lost_torque_off(self, reg, value):  # type: ignore[no-untyped-def]
        if reg is ct.TORQUE_ENABLE and value == 0:
            return  # the packet never reached a servo
        real_broadcast(self, reg, value)

    monkeypatch.setattr(DxlBus, "broadcast_write", lost_torque_off)
    r = CliRunner().invoke(app, ["check", str(_config(tmp_path))], terminal_width=400)
    said = " ".join(r.output.split())
    assert "torque then released" not in said and "are limp" not in said, said
    assert "torque-off sent" in said and "Torque Enable reads back ON from servo 1" in said, said
    # an emulated chain has no power switch but keeps its torque into the next command, as
    # a powered chain does: its power cycle is deleting its kept state, said to be pasted
    assert "switch the servos' power off and on" not in said, said
    assert "to release it, support the arm and delete " in said, said
    assert "(where the emulated servos' powered state and latched errors are kept" in said, said
    (emu,) = emulators  # the truth: both still hold
    assert all(s.get(ct.TORQUE_ENABLE) == 1 for s in emu.servos.values())
