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


def test_a_second_stop_during_a_hung_opening_ends_it_there(
    port: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An opening that hangs (a wedged USB adapter) had held every Ctrl-C and SIGTERM until it
    returned: the user's only way out was SIGKILL, which skips the teardown's all-off."""
    import signal

    from rti_rig.core.deferred_signals import signal_handlers

    real_open = os.open
    reached: list[str] = []

    def hung_open(file, flags, *args, **kwargs):  # type: ignore[no-untyped-def]
        if os.fspath(file) == port:  # the system's open waits; the user presses Ctrl-C twice
            signal.raise_signal(signal.SIGINT)
            signal.raise_signal(signal.SIGINT)
            reached.append("the open returned")
        return real_open(file, flags, *args, **kwargs)

    def stop(signum: int, frame: object) -> None:
        raise InjectedStop

    before = descriptors_on(port)
    transport = SerialTransport(port)
    monkeypatch.setattr(os, "open", hung_open)
    with signal_handlers({signal.SIGINT: stop}), pytest.raises(InjectedStop):
        transport.open()
    monkeypatch.setattr(os, "open", real_open)
    assert reached == []  # held until the open returned: the second Ctrl-C did nothing
    transport.close()
    assert descriptors_on(port) == before
