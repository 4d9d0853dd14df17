"""A failed arm move is named by the pose it was going to, not by a numpy array.

A servo that overloads mid-run (``[[emulator.faults]]`` on the shipped arm) stops ``rti-rig
run`` with the arm's error. Its operation had been said as the unit vector's numpy repr
(``arm during 'move_to [0.9968 0.     0.0805]': …``), which names nothing a user can find in
the .lp, the check's table or on the rig.
"""

from __future__ import annotations

import re
from pathlib import Path

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
    assert -180 <= float(move.group(1)) <= 180 and 0 <= float(move.group(2)) <= 90
