"""A failed arm move is named by the pose it was going to, not by a numpy array.

A servo that overloads mid-run (``[[emulator.faults]]`` on the shipped arm) stops ``rti-rig
run`` with the arm's error. Its operation had been said as the unit vector's numpy repr
(``arm during 'move_to [0.9968 0.     0.0805]': …``), which names nothing a user can find in
the .lp, the check's table or on the rig.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from conftest import inprocess_arm_config, said, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_a_move_that_faults_is_named_by_its_azimuth_and_elevation(tmp_path: Path) -> None:
    cfg = inprocess_arm_config(tmp_path, servo_fault(60, 2))
    r = runner.invoke(
        app, ["run", str(cfg), "--lights", "6", "--out", str(tmp_path / "s")], terminal_width=400
    )
    words = said(r)
    assert r.exit_code == 2, words
    assert "Traceback" not in words and "move_to" not in words, words
    move = re.search(r"arm during 'move to az (-?\d+\.\d)°, el (-?\d+\.\d)°': servo 2", words)
    assert move is not None, words
    # the first light of the homogeneous layout, as the .lp frame names it
    assert 0 <= float(move.group(1)) < 360 and 0 <= float(move.group(2)) <= 90


def test_a_light_a_turn_from_the_joints_range_is_named_by_its_own_azimuth(
    tmp_path: Path,
) -> None:
    """The shipped arm's azimuth joint turns -170..170°, so a light at az 200° (as the .lp
    and rti-rig's other words give it, 0-360°) is reached at the joint's -160°: its failed
    move had been named "az -160.0°", an azimuth no light of the plan has. The light's own
    azimuth is said, and the joint's angle beside it."""
    azimuths = (200.0, 215.0, 230.0, 245.0, 260.0, 250.0)
    rows = []
    for k, az in enumerate(azimuths):
        a, e = np.radians(az), np.radians(30.0 + 5 * k)
        rows.append(
            f"light_{k} {np.cos(e) * np.cos(a):.6f} {np.cos(e) * np.sin(a):.6f} {np.sin(e):.6f}"
        )
    plan = tmp_path / "plan.lp"
    plan.write_text(f"{len(rows)}\n" + "\n".join(rows) + "\n")
    cfg = inprocess_arm_config(tmp_path, servo_fault(60, 2))
    r = runner.invoke(
        app,
        ["run", str(cfg), "--plan", str(plan), "--out", str(tmp_path / "s")],
        terminal_width=400,
    )
    words = said(r)
    assert r.exit_code == 2, words
    assert "Traceback" not in words, words
    move = re.search(
        r"arm during 'move to az (\d+\.\d)°, el (\d+\.\d)° \(azimuth joint at (-\d+\.\d)°\)'",
        words,
    )
    assert move is not None, words
    az, joint = float(move.group(1)), float(move.group(3))
    assert min(abs(az - a) for a in azimuths) < 0.1, words
    assert abs(joint - (az - 360.0)) < 0.1, words
