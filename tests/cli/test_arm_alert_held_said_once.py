"""A servo that alerts for a fault it does not shut down for (an input-voltage error on an
XL430: Shutdown 0x34) is still driven, so a stop holds it like the other joint.

A run's teardown stops the arm twice (its stop, then the close's), and each stop said the
fault's whole paragraph of advice again: with the error itself, the same paragraph was printed
three times at the end of the session. The error now says it, once; the stops' hold is a
detail kept off the terminal."""

from __future__ import annotations

from pathlib import Path

from conftest import run_faulted_arm


def test_a_servo_held_despite_its_alert_is_said_once(tmp_path: Path) -> None:
    # the azimuth servo's supply error as the session moves the arm: it keeps its torque on
    said = run_faulted_arm(tmp_path, "input_voltage")
    assert "servo 1: hardware fault input voltage" in said, said  # the error that ended it
    # the error says it, once; the stop's hold of the servo is a detail, never a second telling
    assert "held despite a hardware alert" not in said, said
    assert said.count("its torque is still ON") == 1, said
