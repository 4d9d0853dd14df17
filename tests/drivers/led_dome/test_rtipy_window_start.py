"""RTIPy's sketch prints ``I received: … the instructionByte was: T`` and then lights the LED
for ``secs`` whole seconds: the LED lights as the reply starts out of the board's transmit
buffer, so the reply is fully heard one reply on the wire (about 50 ms at 9600 baud) plus the
port's latency after the window began. The driver had counted the window from the reply's
arrival, so it placed the window's end that much after the LED went dark, and an all-off just
before that end (the capture over, in the driver's eyes, inside the window) was taken as a
capture under a lit LED while the board was already dark.

Whatever the driver says must hold on the board: an all-off that does not refuse the capture
comes while the LED is still lit (the emulator's timeline is the truth)."""

from __future__ import annotations

import sys
import time

import pytest

from rti_rig.core.dome_link import DomeLedError
from rti_rig.drivers.led_dome.factory import build_driver
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]


@pytest.mark.parametrize("before_end_s", [0.01, 0.03])
def test_an_all_off_the_driver_accepts_comes_while_the_led_is_lit(before_end_s: float) -> None:
    board = board_for("rtipy")
    with serve_on_pty(board, "rtipy") as link:
        settings = DomeSerialSettings(
            port=link.port, profile="rtipy", reply_timeout_s=3.0, protocol={"light_on_s": 1}
        )
        driver = build_driver(settings)
        driver.connect()
        try:
            driver.light(20)
            end = driver._window_end  # where the driver places the LED's going dark
            assert end is not None
            clock = driver.transport.clock
            clock.sleep(max(0.0, end - before_end_s - clock.now()))
            called = time.monotonic()  # the board's clock (a SystemClock) reads the same
            try:
                driver.all_off()
                accepted = True
            except DomeLedError:
                accepted = False  # a late wake-up (a loaded machine): refused, also true
            _ = board.lit  # the board run up to now, so its timeline covers ``called``
            if accepted:
                assert 20 in board.lit_at(called), (called, board.timeline)
        finally:
            driver.close()
