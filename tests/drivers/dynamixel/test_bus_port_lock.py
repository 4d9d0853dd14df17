"""A second opener of the arm's port is refused before it sends anything.

The SDK opens the port unlocked: a second `rti-rig check` on the arm's port while one ran
opened it too, the two shared the servos' replies (the second failed "COMM_RX_TIMEOUT … check
power, cabling, id and baud rate"), and a second one whose pings were answered would have
written position limits (torque off) and goals to an arm the first was moving. The dome's
transport already locks its port as pyserial's ``exclusive=True`` does; the arm's bus now takes
the same lock.
"""

from __future__ import annotations

import sys

import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.dynamixel.bus import DxlBus
from rti_rig.drivers.dynamixel.faults import CommunicationError
from rti_rig.simulator.dynamixel_emulator import arm_settings_of, served_arm

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="flock on a pty, tested on Linux"),
]


def test_a_second_bus_on_the_same_port_is_refused_and_sends_nothing() -> None:
    settings, _ = arm_settings_of(None)
    with served_arm(settings, VirtualClock()) as (server, _emulator):
        first = DxlBus(server.port_handler(), "arm on A")
        first.open(57600)
        heard = server.ledger.host_sent if server.ledger is not None else 0
        second = DxlBus(server.port_handler(), "arm on B")
        with pytest.raises(CommunicationError, match="is locked by another program") as info:
            second.open(57600)
        assert "nothing was sent" in str(info.value)
        assert server.ledger is not None and server.ledger.host_sent == heard
        assert not second.port.is_open
        first.close()
        # the lock goes with the port: the next opener gets it
        third = DxlBus(server.port_handler(), "arm on C")
        third.open(57600)
        third.close()
