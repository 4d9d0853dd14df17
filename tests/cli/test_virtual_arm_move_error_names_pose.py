"""The virtual arm's failed move is named by its azimuth and elevation, as the real arm's is.

The Dynamixel arm's errors name a move by the pose it was going to ("move to az 12.0°, el
30.0°"); the virtual arm (``backend = "simulated"``) and the fault campaign's failing arm had
still said the code name, ``arm during 'move_to': …``, which names nothing on the rig.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.clock import VirtualClock
from rti_rig.core.errors import DeviceError
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.core.rig_geometry import ArmGeometry
from rti_rig.simulator import sim_lights
from rti_rig.simulator.faults import FaultPlan, FaultyCarrier

runner = CliRunner()


def test_a_failed_virtual_arm_move_is_named_by_its_pose(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``rti-rig run`` on the shipped virtual arm whose second move fails (the fault
    campaign's injected arm fault), through the composition root."""
    real_arm = sim_lights.SimulatedArm

    def failing_arm(*args, **kwargs):  # type: ignore[no-untyped-def]
        return FaultyCarrier(real_arm(*args, **kwargs), FaultPlan("arm-jam", at=1))

    monkeypatch.setattr(sim_lights, "SimulatedArm", failing_arm)
    out = tmp_path / "s"
    r = runner.invoke(
        app,
        ["run", str(CONFIGS / "virtual_arm.toml"), "--lights", "6", "--out", str(out)],
        terminal_width=400,
    )
    words = said(r)
    assert r.exit_code == 2 and "Traceback" not in words, words
    assert "move_to" not in words, words
    move = re.search(
        r"during 'move to az (\d+\.\d)°, el (\d+\.\d)°(?: \(azimuth joint at -?\d+\.\d°\))?': "
        "injected fault",
        words,
    )
    assert move is not None, words
    assert 0 <= float(move.group(1)) < 360 and 5 <= float(move.group(2)) <= 80


def test_a_light_a_turn_from_the_virtual_joint_is_named_by_its_own_azimuth(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The virtual arm's azimuth joint turns -180..180°, so a light at az 200° (as the .lp
    and rti-rig's other words give it, 0-360°) is reached at the joint's -160°: its failed
    move had been named "az -160.0°", an azimuth no light of the plan has, after the
    Dynamixel arm's errors had been corrected to say the light's own azimuth."""
    real_arm = sim_lights.SimulatedArm

    def failing_arm(*args, **kwargs):  # type: ignore[no-untyped-def]
        return FaultyCarrier(real_arm(*args, **kwargs), FaultPlan("arm-jam", at=0))

    monkeypatch.setattr(sim_lights, "SimulatedArm", failing_arm)
    rows = []
    for k, az in enumerate((200.0, 215.0, 230.0, 245.0, 260.0, 275.0)):
        d = direction_from_az_el(az, 30.0 + 5 * k)
        rows.append(f"light_{k} {d[0]:.6f} {d[1]:.6f} {d[2]:.6f}")
    plan = tmp_path / "plan.lp"
    plan.write_text(f"{len(rows)}\n" + "\n".join(rows) + "\n")
    r = runner.invoke(
        app,
        [
            "run",
            str(CONFIGS / "virtual_arm.toml"),
            "--plan",
            str(plan),
            "--out",
            str(tmp_path / "s"),
        ],
        terminal_width=400,
    )
    words = said(r)
    assert r.exit_code == 2 and "Traceback" not in words, words
    move = re.search(
        r"during 'move to az (\d+\.\d)°, el (\d+\.\d)° \(azimuth joint at (-\d+\.\d)°\)': "
        "injected fault",
        words,
    )
    assert move is not None, words
    az, joint = float(move.group(1)), float(move.group(3))
    assert 200.0 <= az <= 275.0 and abs(joint - (az - 360.0)) < 0.1, words


def test_a_refused_virtual_arm_move_is_named_by_its_pose() -> None:
    """The arm's own refusals (not connected; a direction it cannot reach) name the pose too."""
    geometry = ArmGeometry(
        min_elevation_deg=5.0,
        max_elevation_deg=80.0,
        keep_out_half_angle_deg=10.0,
        park_azimuth_deg=0.0,
        park_elevation_deg=45.0,
    )
    arm = sim_lights.SimulatedArm(
        geometry,
        sim_lights.LightState(),
        VirtualClock(),
        speed_deg_s=60.0,
        acceleration_deg_s2=120.0,
        resolution_deg=0.087890625,
    )
    below = direction_from_az_el(30.0, 2.0)  # under the arm's 5° floor
    with pytest.raises(DeviceError) as not_connected:
        arm.move_to(below)
    arm.connect()
    with pytest.raises(DeviceError) as refused:
        arm.move_to(below)
    for exc in (not_connected.value, refused.value):
        assert "move_to" not in str(exc) and "move to az 30.0°, el 2.0°" in str(exc), exc
