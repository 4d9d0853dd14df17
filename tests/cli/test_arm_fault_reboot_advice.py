"""The way a hardware fault's error says to clear it is one that works on a real servo.

Every fault had been told "run rti-rig check RIG --reboot-faulted … to clear it". A servo
whose torque stays on through its fault (an input-voltage error on an XL430, whose Shutdown
does not select it) is one that check leaves alone ("NOT rebooted"), so the advice sent the
user to a command that then refused; and nothing said that a Reboot clears a fault only once
its cause is gone (a servo still too hot, or on a supply outside its limits, reports it again).
"""

from __future__ import annotations

from pathlib import Path

from conftest import run_faulted_arm


def _run(tmp_path: Path, kind: str) -> str:
    return run_faulted_arm(tmp_path, kind).split("error: ", 1)[1]  # the error that ended the run


def test_a_fault_that_leaves_torque_on_is_not_sent_to_reboot_faulted(tmp_path: Path) -> None:
    error = _run(tmp_path, "input_voltage")
    assert "hardware fault input voltage" in error, error
    assert "its torque is still ON" in error, error
    assert "--reboot-faulted will not reboot it" in error, error
    assert "--reboot-faulted (it reboots" not in error, error
    assert "support the arm and" in error, error


def test_a_fault_that_shut_the_servo_down_is_cleared_once_its_cause_is_gone(
    tmp_path: Path,
) -> None:
    error = _run(tmp_path, "overload")
    assert "hardware fault overload" in error and "Its torque is off" in error, error
    assert "--reboot-faulted (it reboots the faulted servos whose torque is off" in error, error
    assert "a reboot clears the fault only once its cause is gone" in error, error
