"""The servo bus emulator declares that it hears the host's line speed.

``PtyServoServer`` set ``emulator.host_baud`` on each pass without the emulator declaring
:class:`~rti_rig.simulator.pty_link.HostBaudDevice`: the protocol check (``isinstance`` on a
runtime protocol, which pty_link's server decides by) did not see it as declared, and a
rename on either side would have gone unheard. It is now declared, and the servo server tells
the rate only to a device that declares it.
"""

from __future__ import annotations

import dynamixel_sdk as sdk
import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.simulator.dynamixel_emulator import DynamixelBusEmulator, EmulatedServo
from rti_rig.simulator.dynamixel_pty import PtyServoServer
from rti_rig.simulator.pty_link import HostBaudDevice


def _bus() -> DynamixelBusEmulator:
    clock = VirtualClock()
    return DynamixelBusEmulator([EmulatedServo(1, 1060, clock)], clock)


def test_the_bus_emulator_declares_host_baud_device() -> None:
    assert HostBaudDevice in DynamixelBusEmulator.__mro__
    emu = _bus()
    assert isinstance(emu, HostBaudDevice)
    assert PtyServoServer(emu).host_baud_device is emu


@pytest.mark.pty
def test_the_pty_server_tells_the_declared_device_the_host_s_rate() -> None:
    emu = _bus()
    with PtyServoServer(emu) as server:
        assert server.host_baud_device is emu
        assert server.device_path is not None
        # the SDK's port with the server's causal reply wait: the plain one's 34 ms wall-time
        # window failed this test on a loaded machine (an emulator thread is not a servo)
        port = server.port_handler()
        assert port.openPort() and port.setBaudRate(57600)
        try:
            # the reply comes after the server has set the rate it read from the pty
            assert sdk.PacketHandler(2.0).ping(port, 1)[1] == sdk.COMM_SUCCESS
        finally:
            port.closePort()
    assert emu.host_baud == 57600
