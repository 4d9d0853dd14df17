"""The port's opening and its boot wait, as both dome drivers keep them.

Why a module of its own: :class:`~rti_rig.drivers.led_dome.driver.LedDomeDriver` and
:class:`~rti_rig.drivers.led_dome.scripted.ScriptedDomeDriver` had two copies of the same
bookkeeping (``open_cut_short``, when the boot wait ends, whether it ran out), and the policy's
answer to a stop that cut an opening short (:meth:`reopen_port`, then ``finish_boot``) relies on
every step of it. One copy cannot drift: the line protocol's links had once been fixed for a
stop inside the opening while the other had been left out.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from errno import EACCES

from rti_rig.core.clock import Clock
from rti_rig.core.dome_link import DomeLinkError
from rti_rig.drivers.led_dome.transport import PortHeldError, Transport, TransportError


class PortOpening(ABC):
    """Mixin: :meth:`reopen_port`, :meth:`finish_boot` and the boot wait's state; the driver
    gives the wait's length (:meth:`_boot_wait_s`), the wait itself (:meth:`_wait_out_boot`),
    what to forget of the board at each opening (:meth:`_forget_board`) and the error for a
    port the system refused (:meth:`_refused`).

    Why abstract: a driver lacking one of them had been caught only when a stop called it (a
    ``NotImplementedError`` in the all-off path); now the driver cannot be built."""

    transport: Transport
    _open: bool
    _rx: bytearray
    #: A stop came while the port was being opened (see :meth:`reopen_port`).
    open_cut_short: bool
    #: The wait for the ready banner after the last opening is over (banner or deadline).
    _booted: bool
    #: When the port was last opened and when its boot wait ends (the transport's clock).
    _opened_at: float
    _boot_deadline: float

    @property
    def clock(self) -> Clock:
        """The clock this link's reads wait on: its transport's (``DomeLink.clock``)."""
        return self.transport.clock

    def _init_opening(self) -> None:
        """Set this mixin's state for a link that has opened nothing yet (each driver's
        ``__init__`` calls it: one place, where two drivers had each kept their own copy)."""
        self.open_cut_short = False
        self._booted = False
        self._opened_at = 0.0
        self._boot_deadline = 0.0

    @abstractmethod
    def close(self) -> None:
        """Close the port (each driver's own, which also forgets what the board sent)."""

    @abstractmethod
    def _boot_wait_s(self) -> float:
        """How long the board may take to boot after the port opens."""

    @abstractmethod
    def _wait_out_boot(self) -> None:
        """Wait for the board's ready sign up to :attr:`_boot_deadline` (not a fresh wait),
        then count the boot wait over (:attr:`_booted`)."""

    def _forget_board(self) -> None:
        """Forget what the last opening learnt of the board (nothing by default: a driver
        that learns nothing of the board at an opening need not say so)."""
        return None

    @abstractmethod
    def _refused(self, exc: TransportError) -> DomeLinkError:
        """The error for a port the system would not open (``port_held`` set by the caller)."""

    def finish_boot(self) -> None:
        """Wait out the rest of the boot wait a stopped ``connect`` cut short (to the same
        deadline, not a fresh wait), so that the all-off the policy sends next reaches the
        firmware: bytes sent to a board still in its bootloader are lost (the Nab sketch then
        lights every LED in ``setup()``). Nothing to do once the wait is over or the port is
        closed."""
        if self._open and not self._booted:
            self._wait_out_boot()

    def _start_boot_wait(self) -> None:
        """Count the boot wait (and a slow-boot measure) from now."""
        self._opened_at = self.transport.clock.now()
        self._boot_deadline = self._opened_at + self._boot_wait_s()

    def reopen_port(self) -> None:
        """Open the port (closing it first) and start the boot wait, without waiting it out:
        the first step of ``connect``, and what the policy calls to get the port back for the
        all-off when a stop cut that step short (then ``finish_boot``).

        :attr:`open_cut_short` is true, for a port whose opening may reset the board (a serial
        device's, not a URL's: ``SerialTransport.resets_on_open``), from before the system
        opens the port until this link counts it open. Why: a Ctrl-C or SIGTERM in between
        (inside pyserial's open, which closes the port again as the stop goes through, or just
        after it) left a port this link never had open, so no all-off was sent while the
        opening had reset the board, and the Nab sketch boots with every LED lit."""
        self.close()
        # only an opening that may reset the board leaves one to switch off if a stop cuts it
        # short; a URL port's connect resets nothing (see SerialTransport.resets_on_open)
        self.open_cut_short = self.transport.resets_on_open
        self._booted = False
        self._forget_board()
        # counted from before the opening too: a stop inside it then finds this opening's
        # deadline, not an earlier one's (its all-off would be lost in the bootloader)
        self._start_boot_wait()
        try:
            self.transport.open()
        except TransportError as exc:
            self.open_cut_short = False  # the system refused it: nothing was opened or reset
            error = self._refused(exc)
            error.port_held = isinstance(exc, PortHeldError)
            error.permission_denied = exc.errno == EACCES
            raise error from exc
        self._open = True
        self._rx.clear()
        self.open_cut_short = False
        # and again once open: the board resets as the open completes, and a slow open (a USB
        # adapter that takes its time) had eaten into the boot wait, the first bytes then sent
        # into the bootloader
        self._start_boot_wait()
