"""The profile's boot wait is counted from when the port is open, not from before its opening.

A board that resets on open (the Nab sketch's Uno) starts its bootloader as the open
completes. The boot-wait clock had been started before ``transport.open()`` (kept for a stop
inside the opening), so a slow open (a USB adapter that takes its time) ate into the wait, and
the first command went to a board still in its bootloader, where it is lost."""

from __future__ import annotations

import pytest

from rti_rig.core.clock import VirtualClock
from rti_rig.drivers.led_dome.factory import protocol_for
from rti_rig.drivers.led_dome.scripted import ScriptedDomeDriver
from rti_rig.drivers.led_dome.settings import DomeSerialSettings


class SlowOpeningPort:
    """A port whose opening takes ``open_s`` on the clock, then silent (no board answers)."""

    name = "slow port"
    baudrate = 9600
    resets_on_open = True  # an Uno's: its opening resets the board

    def __init__(self, clock: VirtualClock, open_s: float) -> None:
        self.clock = clock
        self.open_s = open_s
        self.opened_at: float | None = None

    def open(self) -> None:
        self.clock.sleep(self.open_s)
        self.opened_at = self.clock.now()

    def close(self) -> None:
        pass

    def write(self, data: bytes) -> None:
        pass

    def read(self, timeout_s: float) -> bytes:
        self.clock.sleep(timeout_s)
        return b""


def test_a_slow_port_opening_does_not_shorten_the_boot_wait() -> None:
    clock = VirtualClock()
    port = SlowOpeningPort(clock, open_s=1.5)
    spec = protocol_for(DomeSerialSettings(port="slow", profile="nab-rti-v1"))
    driver = ScriptedDomeDriver(port, spec)  # type: ignore[arg-type]
    driver.reopen_port()
    driver.finish_boot()
    assert port.opened_at is not None
    assert clock.now() == pytest.approx(port.opened_at + spec.boot_wait_s)
