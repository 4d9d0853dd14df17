"""A second failure while making the arm safe after a first is said in its own line, never lost.

Before, ``close`` raised its first teardown failure and only logged any later one at error level
("arm: teardown step failed: …"), and a move's timeout logged the stop that then failed ("stop
after timeout failed"): records the command line printed raw, or nowhere at all under a caller
that configures logging. Each is now said through the arm's listener (``run``, ``check``), or
with none as a warning record (the command line says those as notes: tests/cli/
test_records_as_notes.py), and kept in ``arm.said``.
"""

from __future__ import annotations

import logging

import pytest
from dxl_support import arm_settings

from rti_rig.core.clock import VirtualClock
from rti_rig.core.geometry import direction_from_az_el
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel.arm import DynamixelArm
from rti_rig.drivers.dynamixel.faults import CommunicationError, MoveTimeoutError
from rti_rig.simulator.dynamixel_emulator import InProcessPort, emulator_for_arm


def _arm(**overrides):  # type: ignore[no-untyped-def]
    settings = arm_settings(**overrides)
    clock = VirtualClock()
    emu = emulator_for_arm(settings, clock)
    return DynamixelArm(settings, InProcessPort(emu), clock), emu


def _failing(arm: DynamixelArm, monkeypatch: pytest.MonkeyPatch) -> None:
    """Its stop and its torque release fail, as on a bus whose servos stopped answering."""

    def stop() -> None:
        raise CommunicationError(arm.name, "servo 2 did not answer the stop", "stop", 2)

    def release() -> None:
        raise CommunicationError(arm.name, "servo 1 did not answer", "read Present Position", 1)

    monkeypatch.setattr(arm, "stop", stop)
    monkeypatch.setattr(arm, "_release_if_parked", release)


def test_the_second_failure_of_a_close_is_said_to_the_listener(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    arm, _emu = _arm(torque_policy="release_on_close")
    arm.connect()
    heard: list[str] = []
    arm.listen(heard.append)
    _failing(arm, monkeypatch)
    with caplog.at_level(logging.DEBUG), pytest.raises(CommunicationError, match="the stop"):
        arm.close()  # the first failure is raised, for its caller to say
    assert len(heard) == 1, heard
    assert heard[0].startswith("arm: while closing after an earlier failure, the torque release")
    assert "servo 1 did not answer" in heard[0] and "its torque may still be on" in heard[0]
    assert arm.said == heard
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


def test_with_no_listener_the_second_failure_is_a_warning_record_not_lost(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    arm, _emu = _arm(torque_policy="release_on_close")
    arm.connect()
    _failing(arm, monkeypatch)
    with caplog.at_level(logging.DEBUG), pytest.raises(CommunicationError):
        arm.close()
    loud = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert loud == arm.said and len(loud) == 1, loud
    assert "the torque release failed too" in loud[0]


def test_a_stop_that_fails_after_a_move_timeout_is_said_beside_the_timeout(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    arm, emu = _arm(move_timeout_s=2.0, azimuth=dict(min_deg=-20.0, max_deg=20.0))
    arm.connect()
    heard: list[str] = []
    arm.listen(heard.append)
    emu.servos[2].table[ct.TORQUE_ENABLE.address] = 0  # stalls: goal accepted, no motion
    _failing(arm, monkeypatch)
    with pytest.raises(MoveTimeoutError, match="not in position"):
        arm.move_to(direction_from_az_el(0, 60))
    assert len(heard) == 1, heard
    assert heard[0].startswith("arm: the stop after the move timed out failed too: "), heard
    assert "servo 2 did not answer the stop" in heard[0], heard
    assert heard[0].endswith(
        "the arm may still be moving: switch off the servos' power if it is."
    ), heard
