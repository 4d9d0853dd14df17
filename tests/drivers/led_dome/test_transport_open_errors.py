"""A serial port that cannot be opened is named once, with the system's reason.

pyserial's text repeats the port ("could not open port P: [Errno 2] No such file or directory:
'P'"), and the dome's message wrapped it again: the path came three times in one line.
"""

from __future__ import annotations

import errno
import os
import pty

import pytest
import serial

from rti_rig.drivers.led_dome.transport import SerialTransport, TransportError


def test_a_missing_port_is_named_once_with_its_reason(tmp_path) -> None:  # type: ignore[no-untyped-def]
    port = str(tmp_path / "ttyNOPE")
    with pytest.raises(TransportError) as info:
        SerialTransport(port).open()
    assert str(info.value) == f"cannot open serial port {port}: No such file or directory"


@pytest.mark.pty
def test_a_port_another_program_holds_says_so() -> None:
    main, sub = pty.openpty()
    name = os.ttyname(sub)
    holder = serial.Serial(name, exclusive=True)
    try:
        with pytest.raises(TransportError, match="another program holds it"):
            SerialTransport(name).open()
    finally:
        holder.close()
        os.close(main)
        os.close(sub)


def test_a_missing_port_whose_path_says_lock_is_not_called_held(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """The word "lock" in the path had made a missing port "held by another program"."""
    port = str(tmp_path / "usb-Blocksmith_dome")
    with pytest.raises(TransportError) as info:
        SerialTransport(port).open()
    assert str(info.value).endswith("No such file or directory")


@pytest.mark.parametrize(
    ("port", "number"), [("/dev/null", errno.ENOTTY), ("/dev/random", errno.EINVAL), ("", 0)]
)
def test_the_error_carries_the_systems_number(tmp_path, port: str, number: int) -> None:  # type: ignore[no-untyped-def]
    """The system's error number rides on the transport's error, also where pyserial kept it
    only in the ``termios.error`` its own exception was raised from (/dev/null, /dev/random):
    callers decide from it, not from a message's words (``rti-rig probe``)."""
    port, number = port or str(tmp_path / "ttyNOPE"), number or errno.ENOENT
    with pytest.raises(TransportError) as info:
        SerialTransport(port).open()
    assert info.value.errno == number, info.value
