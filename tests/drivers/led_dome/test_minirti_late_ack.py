"""minirti's acknowledgement is one byte, ``0x01``, the same for every command: a late one
cannot be told from the next command's by its content.

The host code it comes from (michaelwh/rticap ``domecontroller.py``; the firmware is not
published) flushes its input before each command and then reads until a ``0x01`` with no
timeout, so it never leaves an acknowledgement behind. This driver gives up after its reply
timeout; the board may still have taken the command and acknowledge it after that. Only the
input already there was dropped before the next command, so a ``0x01`` arriving once the
next command was written was counted as its acknowledgement: a command the board never
acknowledged was said acknowledged. The emulator's ``delay_reply`` fault sends the late
acknowledgement, real bytes on a pty to real pyserial.
"""

from __future__ import annotations

import sys

import pytest
from conftest import eventually

from rti_rig.core.dome_link import DomeLinkError, LinkFault
from rti_rig.drivers.led_dome.factory import build_driver
from rti_rig.drivers.led_dome.settings import DomeSerialSettings
from rti_rig.simulator.dome_firmware import Fault, FaultKind, FaultPlan
from rti_rig.simulator.domes import board_for
from rti_rig.simulator.pty_link import serve_on_pty

pytestmark = [
    pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux"),
    pytest.mark.pty,
]

REPLY_TIMEOUT_S = 3.0
#: The first command's acknowledgement comes this long after the command: after the driver's
#: reply timeout, and before the end of the one more reply timeout it waits for an owed one —
#: half a timeout (1.5 s) from either edge, so a test thread or the emulator's thread held up
#: by a loaded machine cannot move the byte across one (at + 0.3 s a driver read delayed by
#: 0.3 s would have taken it as the first command's own, on time).
LATE_S = REPLY_TIMEOUT_S * 1.5


@pytest.mark.parametrize("second", ["light", "all off"])
def test_a_late_acknowledgement_is_not_counted_for_the_next_command(second: str) -> None:
    faults = FaultPlan.of(
        Fault(1, FaultKind.DELAY_REPLY, delay_s=LATE_S),  # light LED 3: acknowledged late
        Fault(2, FaultKind.DROP_REPLY),  # the next command: taken, never acknowledged
    )
    board = board_for("minirti", faults=faults)
    with serve_on_pty(board, "minirti") as link:
        settings = DomeSerialSettings(
            port=link.port, profile="minirti", reply_timeout_s=REPLY_TIMEOUT_S
        )
        driver = build_driver(settings)
        driver.connect()
        try:
            with pytest.raises(DomeLinkError) as late:
                driver.light(3)
            assert late.value.fault is LinkFault.TIMEOUT
            assert eventually(lambda: board.lit == frozenset({3}))
            with pytest.raises(DomeLinkError) as unanswered:
                if second == "light":
                    driver.light(5)
                else:
                    driver.all_off()
            # the board's only 0x01 since was the late one, owed to light LED 3
            assert unanswered.value.fault is LinkFault.TIMEOUT, unanswered.value
            assert board.commands == 2
            # and the next command's own acknowledgement is its own again
            driver.light(7)
            assert board.lit == frozenset({7})
        finally:
            driver.close()
