"""What ``rti-rig probe`` says when nothing answers: the port may be a Dynamixel arm's.

Servos answer only their own packets (Protocol 2.0: header FF FF FD 00), which no probe sends;
a Dynamixel ping is not sent either, since its bytes could be keys to a dome that never answers.
So probe cannot tell an arm from a silent dome or an empty port, and says the arm as a
possibility, with the command that does talk to an arm. It had said it as a fact ("a servo
arm's port answers none of these probes") to every silent port, a silent dome's included.

A unit test of the result's text: the probes themselves listen in real time (about 25 s on a
silent port), which the probe tests of each firmware cover."""

from __future__ import annotations

from rti_rig.app.usecases.probe import ProbeResult


def test_nothing_answered_says_an_arm_port_as_a_possibility_with_the_command_for_it() -> None:
    result = ProbeResult("/dev/ttyUSB0", heard=[("listen at 9600 baud", "")])
    said = " ".join(" ".join(result.lines()).split())
    assert "No known dome firmware answered" in said, said
    assert "If this is a servo arm's port (Dynamixel servos), silence is all probe" in said, said
    assert "for an arm, run rti-rig check on its rig config" in said, said
    assert "answers none of these probes" not in said, said


def test_a_firmware_found_gets_no_arm_advice() -> None:
    result = ProbeResult("/dev/ttyACM0", profile="nab-rti-v1", baudrate=9600)
    assert "servo arm" not in " ".join(result.lines())
