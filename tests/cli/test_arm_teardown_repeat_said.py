"""A teardown step of ``run`` that failed as an earlier one did says what it tried and what is
known after it, not a bare pointer.

The arm's close stops it again, so an arm fault failed the stop and then the close with the
same error; the close was said as "light close: failed as 'stop' above", which told a user
neither what had failed nor in what state the lights and the arm were left.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from conftest import inprocess_arm_config, servo_fault


def test_the_close_failing_as_the_stop_did_is_said_plainly(tmp_path: Path) -> None:
    cfg = inprocess_arm_config(tmp_path, servo_fault(150, 1, "overload"))
    run = ["run", str(cfg), "--lights", "12", "--out", str(tmp_path / "s"), "--no-verdict"]
    r = subprocess.run(
        [sys.executable, "-m", "rti_rig", *run],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "COLUMNS": "400"},
    )
    said = " ".join((r.stdout + r.stderr).split())
    assert r.returncode == 2 and "Traceback" not in said, said
    assert "teardown problem: stop: " in said, said
    assert (
        "teardown problem: light close: failed with the same error as 'stop' above; nothing "
        "more was established of the lights or the arm than the 'stop' line says"
    ) in said, said
    assert "failed as 'stop' above" not in said, said
