"""``rti-rig check`` on an arm whose ``torque_policy = "release_on_close"`` says that the park
pose is not held once its torque is released.

A limp elevation joint is back-driven by the lamp's weight (the emulator models it falling to
its lower limit at 10 °/s, an assumption: docs/protocols/dynamixel-arm.md). The check had said
"parked" and no more, of a pose the arm then left."""

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
    assert 'parked; torque then released (torque_policy = "release_on_close")' in said, said
    assert "may lower the elevation joint from 10° towards its lower limit (0°)" in said, said
    assert 'set torque_policy = "hold"' in said
    (emu,) = emulators  # the truth: the torque really is off, so the pose is not held
    assert all(s.get(ct.TORQUE_ENABLE) == 0 for s in emu.servos.values())


def test_a_released_park_at_the_lower_limit_says_it_rests_there(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    r = CliRunner().invoke(
        app, ["check", str(_config(tmp_path, park_elevation_deg=0.0))], terminal_width=400
    )
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "torque then released" in said and "may lower" not in said, said
