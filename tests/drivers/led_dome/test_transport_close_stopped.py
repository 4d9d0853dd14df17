"""A stop (any BaseException: the CLI's emergency stop is raised where its signal lands) inside
pyserial's close of the dome's port.

Cut short as the close began, the port's descriptor stayed open, and with it the exclusive lock,
held by the port object the stop's traceback keeps alive: a teardown reopening the port in the
stop's handler (``rti-rig probe`` switching a Nab dome off) was told another program holds it.
Cut short just after pyserial's own ``os.close``, a second close must not close whatever file
has since been given the same descriptor number.
"""

from __future__ import annotations

import os
import pty
import sys
from collections.abc import Iterator

import pytest
import serial

from rti_rig.drivers.led_dome.transport import SerialTransport

pytestmark = [
    pytest.mark.pty,
    pytest.mark.skipif(sys.platform != "linux", reason="flock on a pty, tested on Linux"),
]


class Stop(BaseException):
    """Stands for the CLI's emergency stop (a BaseException raised where a signal lands)."""


@pytest.fixture
def port() -> Iterator[str]:
    main, sub = pty.openpty()
    try:
        yield os.ttyname(sub)
    finally:
        os.close(main)
        os.close(sub)


def test_a_stop_as_the_close_begins_releases_the_lock_before_it_goes_on(
    port: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_close = serial.Serial.close
    stops: list[int] = []

    def stopped_first(self: serial.Serial) -> None:
        if not stops:
            stops.append(1)
            raise Stop
        real_close(self)

    first = SerialTransport(port)
    first.open()
    monkeypatch.setattr(serial.Serial, "close", stopped_first)
    try:
        first.close()
    except Stop:  # the stop's handler runs here, its traceback alive: the port reopened
        again = SerialTransport(port)
        again.open()  # raised PortHeldError: the cut close had kept the descriptor locked
        again.close()
    else:
        pytest.fail("the close was never cut short")
    assert stops


def test_a_stop_after_pyserials_own_close_does_not_close_a_reused_descriptor(
    port: str, monkeypatch: pytest.MonkeyPatch, tmp_path
) -> None:  # type: ignore[no-untyped-def]
    other: list[int] = []

    def closed_then_stopped(self: serial.Serial) -> None:
        if not other:
            number = self.fd
            os.close(number)  # pyserial's os.close, then the stop before it forgets the number
            reused = os.open(tmp_path / "other", os.O_CREAT | os.O_RDWR)
            other.append(reused)
            assert reused == number, "the descriptor number was not reused: nothing tested"
            raise Stop
        real_close(self)  # the close run again after the stop: it must see the number gone

    real_close = serial.Serial.close
    t = SerialTransport(port)
    t.open()
    monkeypatch.setattr(serial.Serial, "close", closed_then_stopped)
    with pytest.raises(Stop):
        t.close()
    try:
        os.fstat(other[0])  # still open: the second close left another file's descriptor be
    finally:
        os.close(other[0])
