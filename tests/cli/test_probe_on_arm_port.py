"""What ``rti-rig probe`` says when nothing answers: the port may be a Dynamixel arm's.

Servos answer only their own packets (Protocol 2.0: header FF FF FD 00), which no probe sends;
a Dynamixel ping is not sent either, since its bytes could be keys to a dome that never answers.
So probe cannot tell an arm from a silent dome or an empty port, and says the arm as a
possibility, with the command that does talk to an arm. It had said it as a fact ("a servo
arm's port answers none of these probes") to every silent port, a silent dome's included.

The text is a unit test of the result: the probes listen in real time (about 25 s on a silent
port). That no Dynamixel packet is sent is tested through the command line on an arm's port
whose time is virtual (each read that finds nothing advances it by its timeout), the bytes
probe writes fed to the emulated servos of the shipped arm: the claim had no test."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest
from typer.testing import CliRunner

import rti_rig.app.usecases.probe as probe_usecase
from rti_rig.app.usecases.probe import Heard, ProbeResult
from rti_rig.cli import app
from rti_rig.core.clock import VirtualClock
from rti_rig.simulator.dynamixel_emulator import arm_settings_of, emulator_for_arm

#: Protocol 2.0's packet header: every instruction packet to a Dynamixel servo starts with it.
DXL2_HEADER = b"\xff\xff\xfd\x00"


def test_nothing_answered_says_an_arm_port_as_a_possibility_with_the_command_for_it() -> None:
    result = ProbeResult("/dev/ttyUSB0", heard=[Heard("listen at 9600 baud", 9600, "")])
    said = " ".join(" ".join(result.lines()).split())
    assert "No known dome firmware answered" in said, said
    assert "If this is a servo arm's port (Dynamixel servos), silence is all probe" in said, said
    assert "for an arm, run rti-rig check on its rig config" in said, said
    assert "answers none of these probes" not in said, said


def test_a_firmware_found_gets_no_arm_advice() -> None:
    result = ProbeResult("/dev/ttyACM0", profile="nab-rti-v1", baudrate=9600)
    assert "servo arm" not in " ".join(result.lines())


class _ArmPort:
    """A serial port (pyserial's side of it) with the shipped arm's servos on the line: they
    take every byte written and answer only their own instruction packets; a read that finds
    nothing waits its timeout (at least 1 ms) on ``clock``."""

    def __init__(self, bus: Any, clock: VirtualClock, written: list[bytes], **kwargs: Any):
        self._bus, self._clock, self._written = bus, clock, written
        self.timeout = kwargs.get("timeout")
        self._pending = bytearray()

    @property
    def in_waiting(self) -> int:
        return len(self._pending)

    def write(self, data: bytes) -> int:
        self._written.append(bytes(data))
        self._pending += self._bus.receive(bytes(data))
        return len(data)

    def flush(self) -> None:
        pass

    def read(self, n: int) -> bytes:
        if not self._pending:
            # a read with timeout 0 takes its time too (the probe's listen rounds what is left
            # of its wait to 0.1 ms, then to 0 s: a read that took none never ended that wait)
            self._clock.sleep(max(self.timeout or 0.0, 0.001))
            return b""
        out, self._pending = bytes(self._pending[:n]), self._pending[n:]
        return out

    def close(self) -> None:
        pass


def test_probe_on_an_arm_port_sends_no_dynamixel_packet(monkeypatch: pytest.MonkeyPatch) -> None:
    import serial

    clock = VirtualClock()
    settings, _ = arm_settings_of(None)
    bus = emulator_for_arm(settings, clock)
    written: list[bytes] = []
    opened: list[str] = []

    def open_port(url: str, *args: Any, **kwargs: Any) -> _ArmPort:
        opened.append(url)
        return _ArmPort(bus, clock, written, **kwargs)

    monkeypatch.setattr(serial, "serial_for_url", open_port)
    monkeypatch.setattr(probe_usecase, "time", SimpleNamespace(monotonic=clock.now))
    r = CliRunner().invoke(app, ["probe", "/dev/ttyUSB0"], terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 1 and "Traceback" not in said, said
    assert "If this is a servo arm's port (Dynamixel servos), silence is all probe" in said, said
    assert opened and written, (opened, written)  # the probes that send bytes did send them
    assert not any(DXL2_HEADER in data for data in written), written
    assert DXL2_HEADER not in b"".join(written)
    assert bus.instructions == [], bus.instructions  # no servo took a packet of its own
