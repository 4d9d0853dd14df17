"""Byte transports for the dome driver: the real serial port, or anything that behaves like it.

The driver never touches pyserial directly; it is handed a :class:`Transport`, so the same driver
runs on a USB serial port, on the emulator over a pseudo-terminal (still real pyserial), or on
the emulator in-process (``rti_rig.simulator.dome_firmware.InProcessDomeTransport``).

A transport carries the clock its reads wait on: real ports wait in real time whatever clock the
rig uses, while the in-process emulator waits on the simulation's clock. The driver measures its
reply deadlines on ``transport.clock`` so the two never disagree.
"""

from __future__ import annotations

import contextlib
import os
from errno import EACCES, ENOENT
from typing import Protocol

import serial

from rti_rig.core.clock import Clock, SystemClock
from rti_rig.core.deferred_signals import signals_deferred
from rti_rig.drivers.ports_present import ports_present_note
from rti_rig.drivers.serial_ports import (
    PORT_ERRORS,
    TERMIOS_ERROR,
    finish_close,
    identity,
    permission_denied_why,
)


class TransportError(Exception):
    """The port is gone (unplugged, closed under us) or cannot be opened.

    ``errno`` is the system's error number behind it, when there is one (the ``OSError`` or
    ``termios.error`` that pyserial raised or wrapped), so that a caller decides from the number
    what the failure means (``rti-rig probe``: ENOTTY is a device that is no terminal) rather
    than from the words of a message, which change with pyserial's version and the locale.
    """

    def __init__(self, message: str, *, errno: int | None = None) -> None:
        super().__init__(message)
        self.errno = errno


class PortHeldError(TransportError):
    """The port exists but another program holds its lock (another rti-rig on this dome)."""


class Transport(Protocol):
    """A byte pipe to the board. Opened by :meth:`open`, never in the constructor."""

    #: Human name of the endpoint (port path), used in error messages.
    name: str
    #: The clock :meth:`read` waits on.
    clock: Clock

    @property
    def resets_on_open(self) -> bool:
        """Opening this port may reset the board (a serial device's DTR): a stop inside the
        opening then leaves a board to switch off (see ``PortOpening.reopen_port``). Declared,
        not looked up with a default: a transport lacking it had silently been taken for one
        that resets."""
        ...

    def open(self) -> None: ...

    def close(self) -> None:
        """Release the port; safe twice."""
        ...

    def write(self, data: bytes) -> None: ...

    def read(self, timeout_s: float) -> bytes:
        """Bytes available now, waiting up to ``timeout_s`` for the first; ``b""`` on timeout."""
        ...


class SerialTransport:
    """A pyserial port (``serial_for_url``, so ``loop://`` and ``socket://`` work too).

    Opening the port toggles DTR, which resets most Arduino boards: the driver then waits for the
    board's ready banner rather than sleeping a fixed time.
    """

    def __init__(
        self,
        port: str,
        baudrate: int = 115200,
        write_timeout_s: float = 1.0,
        given_to: str | None = None,
    ) -> None:
        self.name = port
        self.port = port
        #: The command the port was given to as its argument (``rti-rig probe``), which a
        #: missing port's error says again with the ports present; None: a rig config's port.
        self.given_to = given_to
        self.baudrate = baudrate
        self.write_timeout_s = write_timeout_s
        self.clock: Clock = SystemClock()
        self._ser: serial.SerialBase | None = None
        self._timeout: float | None = None
        #: the open port's file (device, inode), to tell it from a descriptor number reused
        self._opened_as: tuple[int, int] | None = None

    @property
    def resets_on_open(self) -> bool:
        """Opening this port may reset the board: the system's open of a serial device raises
        DTR, which resets most Arduino boards. A URL port (``socket://``, ``rfc2217://``,
        ``loop://`` …) is a network connection or an in-memory loop: connecting toggles no DTR
        here. Why it is asked: a stop inside the opening of such a port had been taken for one
        that may have reset the board, and the policy reopened a connection that never
        completed (a second 5 s connect, signals held) and then said the lights "may still be
        on" of a dome it had never reached."""
        return "://" not in self.port

    @property
    def is_open(self) -> bool:
        """The port is open, this transport's to close. Also after :meth:`open` raised a stop
        held over the opening: the hold acts on it once the port is this transport's, so the
        caller holds an open (and locked) port, where one cut short inside pyserial's open has
        none. Why asked: a caller that took every stop out of :meth:`open` for the latter
        opened the port again while this one still held its lock."""
        return self._ser is not None

    def open(self) -> None:
        """Open (and lock) the port; nothing to do if it is open.

        A device path is opened with SIGINT/SIGTERM held (:func:`signals_deferred`), the stop
        acted on once the port is this transport's: pyserial keeps the system's descriptor
        only once ``os.open`` has returned, so a stop landing in between (the CLI's emergency
        stop is raised wherever its signal lands) left a descriptor no object knew, open until
        the process ended (and the board's line held up, so the teardown's reopening for the
        all-off did not reset it). A device's opening is short (non-blocking open, termios
        calls) but can hang (a wedged USB adapter): a second stop ends the hold at once
        (``second_stops``), so Ctrl-C twice or SIGTERM after Ctrl-C still stops it. A URL
        port's connect may wait (a socket's, seconds), and its socket object closes as the
        stop drops it, so a URL is opened as before, unheld."""
        if self._ser is not None:
            return
        # A second program on the same port would interleave its bytes with ours: lock it
        # (POSIX device paths only; URL handlers such as loop:// have nothing to lock).
        lock = {"exclusive": True} if "://" not in self.port and os.name == "posix" else {}
        held = (
            signals_deferred(second_stops=True) if self.resets_on_open else contextlib.nullcontext()
        )
        try:
            with held:
                ser = serial.serial_for_url(
                    self.port,
                    baudrate=self.baudrate,
                    timeout=0,
                    write_timeout=self.write_timeout_s,
                    **lock,
                )
                self._ser, self._opened_as, self._timeout = ser, identity(ser), 0
        except (*PORT_ERRORS, ValueError) as exc:
            # pyserial's text repeats the port twice ("could not open port P: [Errno 2] No such
            # file or directory: 'P'"): the system's reason alone, where it gives one
            errno = getattr(exc, "errno", None)
            if "exclusively lock" in str(exc):  # pyserial's words (the path may hold "lock")
                why = "another program holds it (it could not be locked)"
            elif isinstance(errno, int) and errno > 0:
                why = os.strerror(errno)
            else:
                why = str(exc)
            error = PortHeldError if "exclusively lock" in str(exc) else TransportError
            if errno == ENOENT:  # the device went (or came back under another name)
                note = ports_present_note(self.port, self.given_to)
                why += f"; {note}" if note else ""
            elif errno == EACCES:  # there, but not this user's to open: say what to do
                why = permission_denied_why(self.port)
            raise error(
                f"cannot open serial port {self.port}: {why}", errno=_system_errno(exc)
            ) from exc

    def close(self) -> None:
        """Release the port (its descriptor, and with it the lock ``open`` took); safe twice.

        A stop raised inside pyserial's close (the CLI's emergency stop is raised wherever its
        signal lands, here as the close begins) had left the descriptor open, its lock held by
        the port object that the stop's traceback keeps alive: the stop's teardown then failed
        to reopen the port to switch a Nab dome off ("another program holds it (it could not
        be locked)"), and the dome stayed lit. The close is finished before the stop goes on
        (the CLI raises only the first signal, so the second close runs through)."""
        ser = self._ser
        if ser is None:
            return
        try:
            with contextlib.suppress(*PORT_ERRORS):  # already gone: closing is best effort
                ser.close()
        except BaseException:
            finish_close(ser, self._opened_as)
            raise
        finally:
            self._ser, self._opened_as = None, None

    def write(self, data: bytes) -> None:
        ser = self._require()
        try:
            ser.write(data)
            ser.flush()
        except PORT_ERRORS as exc:
            raise TransportError(
                f"write to {self.port} failed: {exc}", errno=_system_errno(exc)
            ) from exc

    def read(self, timeout_s: float) -> bytes:
        ser = self._require()
        timeout = max(0.0, round(timeout_s, 4))
        try:
            if timeout != self._timeout:
                ser.timeout = timeout
                self._timeout = timeout
            first = ser.read(1)
            if not first:
                return b""
            waiting = ser.in_waiting
            return first + (ser.read(waiting) if waiting else b"")
        except PORT_ERRORS as exc:
            raise TransportError(
                f"read from {self.port} failed: {exc}", errno=_system_errno(exc)
            ) from exc

    def _require(self) -> serial.SerialBase:
        if self._ser is None:
            raise TransportError(f"serial port {self.port} is not open")
        return self._ser


def _system_errno(exc: BaseException) -> int | None:
    """The system's error number behind ``exc``: its own (an ``OSError``, or pyserial's
    ``SerialException`` built from one), else that of the ``termios.error`` it was raised from
    (pyserial's "Could not configure port: (25, ...)" keeps the number only in its text and in
    the exception it was raised while handling); None when the system gave none."""
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        seen.add(id(cause))
        number = getattr(cause, "errno", None)
        if number is None and TERMIOS_ERROR is not None and isinstance(cause, TERMIOS_ERROR):
            number = cause.args[0] if cause.args else None  # termios.error(errno, text)
        if isinstance(number, int) and number > 0:
            return number
        cause = cause.__cause__ or cause.__context__
    return None
