"""A stop (the CLI's emergency stop, raised where its signal lands) as the system opens the
dome's port, before pyserial keeps the descriptor it returned.

That descriptor had been known to no object: open until the process ended (the board's line
held up, so the teardown's reopening for the all-off would not reset it). The transport now
opens a device with SIGINT/SIGTERM held, the stop acted on once the port is its own, so the
teardown's close releases it.
"""

from __future__ import annotations

import os
import pty
import sys
from collections.abc import Iterator

import pytest
from conftest import InjectedStop, descriptors_on, sigint_as_the_system_opens

from rti_rig.drivers.led_dome.transport import SerialTransport

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="/proc/self/fd, flock on a pty: Linux"),
]


@pytest.fixture
def port() -> Iterator[str]:
    main, sub = pty.openpty()
    try:
        yield os.ttyname(sub)
    finally:
        os.close(main)
        os.close(sub)


def test_a_stop_as_the_system_opens_the_port_leaves_no_descriptor_behind(port: str) -> None:
    before = descriptors_on(port)
    transport = SerialTransport(port)
    with sigint_as_the_system_opens(port) as opened:
        try:
            transport.open()
        except InjectedStop:  # the stop's teardown runs here, its traceback alive
            assert opened, "the port was never opened: nothing tested"
            transport.close()
            assert descriptors_on(port) == before  # a descriptor had stayed open, unknown
            again = SerialTransport(port)
            again.open()
            again.close()
        else:
            pytest.fail("the stop was swallowed: it must still end what it stopped")
    assert descriptors_on(port) == before


def test_a_url_port_is_opened_unheld(monkeypatch: pytest.MonkeyPatch) -> None:
    """A URL's connect may wait seconds (a socket's): a stop there is not held."""
    import rti_rig.drivers.led_dome.transport as transport_module

    def held() -> None:
        raise AssertionError("signals held over a URL port's connect")

    monkeypatch.setattr(transport_module, "signals_deferred", held)
    transport = SerialTransport("loop://")
    transport.open()
    transport.close()
