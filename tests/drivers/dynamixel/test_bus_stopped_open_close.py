"""A stop (the CLI's emergency stop, raised where its signal lands) inside the opening or the
closing of the arm's port, which the bus locks with ``flock`` as the dome's transport does.

As the system opened the port, before pyserial kept the descriptor: it stayed open, known to
no object, until the process ended. As the SDK's close began: the descriptor and its lock were
kept (a second ``rti-rig`` was told the port "is locked by another program"), and the SDK still
counted the port open. Just after pyserial's own ``os.close``: a later close closed whatever
file had since been given the same number.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from typing import Any

import pytest
import serial
from conftest import InjectedStop, descriptors_on, sigint_as_the_system_opens

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel.bus import DxlBus
from rti_rig.simulator.dynamixel_emulator import arm_settings_of, served_arm

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="/proc/self/fd, flock on a pty: Linux"),
]


@pytest.fixture
def server() -> Iterator[Any]:
    settings, _ = arm_settings_of(None)
    with served_arm(settings, VirtualClock()) as (served, _emulator):
        yield served


def test_a_stop_as_the_system_opens_the_port_leaves_no_descriptor_behind(server: Any) -> None:
    port = server.device_path
    before = descriptors_on(port)
    bus = DxlBus(server.port_handler(), "arm")
    with sigint_as_the_system_opens(port) as opened:
        try:
            bus.open(57600)
        except InjectedStop:  # the arm's teardown runs here, its traceback alive
            assert opened, "the port was never opened: nothing tested"
            bus.close()
            assert descriptors_on(port) == before  # a descriptor had stayed open, unknown
        else:
            pytest.fail("the stop was swallowed: it must still end what it stopped")
    again = DxlBus(server.port_handler(), "arm again")
    again.open(57600)
    again.close()
    assert descriptors_on(port) == before


def test_a_stop_as_the_close_begins_releases_the_lock_before_it_goes_on(
    server: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_close = serial.Serial.close
    stops: list[int] = []

    def stopped_first(self: serial.Serial) -> None:
        if not stops:
            stops.append(1)
            raise InjectedStop
        real_close(self)

    bus = DxlBus(server.port_handler(), "arm")
    bus.open(57600)
    monkeypatch.setattr(serial.Serial, "close", stopped_first)
    try:
        bus.close()
    except InjectedStop:  # the stop's handler runs here, its traceback alive
        other = DxlBus(server.port_handler(), "arm from a second rti-rig")
        other.open(57600)  # raised "is locked by another program": the lock had been kept
        other.close()
        assert not bus.port.is_open  # the SDK had still counted it open
    else:
        pytest.fail("the close was never cut short")


def test_a_stop_after_pyserials_own_close_does_not_close_a_reused_descriptor(
    server: Any, monkeypatch: pytest.MonkeyPatch, tmp_path
) -> None:  # type: ignore[no-untyped-def]
    other: list[int] = []

    def closed_then_stopped(self: serial.Serial) -> None:
        if not other:
            number = self.fd
            os.close(number)  # pyserial's os.close, then the stop before it forgets the number
            reused = os.open(tmp_path / "other", os.O_CREAT | os.O_RDWR)
            other.append(reused)
            assert reused == number, "the descriptor number was not reused: nothing tested"
            raise InjectedStop
        real_close(self)

    real_close = serial.Serial.close
    bus = DxlBus(server.port_handler(), "arm")
    bus.open(57600)
    monkeypatch.setattr(serial.Serial, "close", closed_then_stopped)
    with pytest.raises(InjectedStop):
        bus.close()
    try:
        bus.close()  # the teardown's close, once more: the port is already closed
        os.fstat(other[0])  # still open: no close reached another file's descriptor
    finally:
        os.close(other[0])
