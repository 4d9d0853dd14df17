"""What ``check --reboot-faulted`` says of a servo (:class:`RebootOutcome`), for statuses the
emulator's named faults do not give: a Hardware Error Status with only bits the e-manual names
no fault for (bit 1, 0x02)."""

from __future__ import annotations

from rti_rig.drivers.dynamixel.arm import RebootOutcome


def test_a_held_servo_with_only_an_unnamed_fault_bit_is_told_to_fix_its_cause() -> None:
    said = RebootOutcome("elevation", 2, status_before=0x02, rebooted=False, torque_on=True)
    text = said.sentence()
    # it had read "hardware fault  (0x02) … the joint would drop; , then support the arm"
    assert "servo 2 (elevation): hardware fault (0x02) but its torque is on" in text, text
    assert "the joint would drop; fix the fault's cause, then support the arm" in text, text
    assert "  " not in text and "; ," not in text, text


def test_a_rebooted_servo_with_only_an_unnamed_fault_bit_has_no_double_space() -> None:
    said = RebootOutcome("azimuth", 1, status_before=0x02, rebooted=True, status_after=0)
    assert said.sentence().startswith("servo 1 (azimuth): hardware fault (0x02); rebooted")
