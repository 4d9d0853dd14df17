"""The one place that talks to the official ``dynamixel_sdk``: checks every result, converts
signed values, and logs every command (the traffic choke point).

Known SDK behaviours handled here:

* 4-byte reads come back unsigned -> :meth:`DxlBus.read` converts signed registers.
* A unicast Action or ``*TxOnly`` leaves the servo's status reply unread, and it corrupts the
  next read -> the arm never sends those; :meth:`DxlBus.write_no_wait` (the only TxOnly here)
  drains the reply, and :meth:`DxlBus.action` always broadcasts (no reply at all).
* A status packet lost or corrupted on the wire fails one exchange (the SDK returns
  COMM_RX_TIMEOUT or COMM_RX_CORRUPT) -> reads (ping, read) and unicast writes of a value are
  idempotent (writing the same value again leaves the servo as one write does) and retried
  once (:meth:`DxlBus._exchange`). A reboot, an action or a clear is not a write of a value
  and is never retried.
* Instruction packets go out without byte stuffing -> harmless for servos (they parse by
  length); the emulator parses by length too.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import os
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

import dynamixel_sdk as sdk
import serial

from rti_rig.core.deferred_signals import signals_deferred
from rti_rig.core.shell_words import shell_word
from rti_rig.drivers.dynamixel import control_table as ct
from rti_rig.drivers.dynamixel import protocol2 as p2
from rti_rig.drivers.dynamixel.faults import (
    CommunicationError,
    DynamixelError,
    HardwareFaultError,
    ServoStatusError,
)
from rti_rig.drivers.ports_present import ports_present_note
from rti_rig.drivers.serial_ports import (
    PORT_ERRORS,
    finish_close,
    identity,
    permission_denied_why,
)

log = logging.getLogger("rti_rig.dynamixel.traffic")

#: How long (ms) the one retry of an exchange whose status did not come within the SDK's reply
#: window waits for its status, and the wait before it for the late one. The SDK's window
#: (``LATENCY_TIMER * 2 + 2`` = 34 ms plus the bytes' wire time, wall time) assumes an adapter
#: whose latency timer is at most 16 ms and a host that reads at once; a slower adapter, or a
#: host (or a pty emulator) too loaded to run within it, gets a present servo's status after
#: the window. The retry had the same window, so two late statuses ended a check or a session
#: with "its cable, or the servos' power supply was lost"; a servo that is really gone costs
#: this once more before the error is said.
PATIENT_REPLY_MS = 500.0

#: SDK communication result codes by name, for error messages (COMM_RX_TIMEOUT, ...).
COMM_NAMES = {getattr(sdk, n): n for n in dir(sdk) if n.startswith("COMM_")}


def comm_text(ph: Any, result: int) -> str:
    return f"{COMM_NAMES.get(result, result)}: {ph.getTxRxResult(result)}"


def no_reply(exc: BaseException) -> bool:
    """Whether ``exc`` is the bus's "no status within the reply window" (the SDK's
    ``COMM_RX_TIMEOUT``), by its result code: not a corrupted status, not a port's failure."""
    return isinstance(exc, CommunicationError) and exc.result == sdk.COMM_RX_TIMEOUT


class _ReleasingHandler:
    """The SDK's packet handler, made safe to interrupt.

    The SDK marks the port in use (``PortHandler.is_using``) when a packet goes out and clears
    the mark only when the exchange completes. A Ctrl-C or SIGTERM raised while an exchange is
    under way (the stop's signal handler raises in the main thread, wherever it is) leaves the
    mark set, and every later packet — the teardown's hold, its torque-off — then fails with
    COMM_PORT_BUSY: the stop could not reach the servos. So an exchange that is interrupted
    releases the port as it unwinds, and the next command first discards the status reply the
    interrupted one may still provoke (it would be read as the next command's answer).

    A port that fails under an exchange (the USB adapter unplugged mid-session: pyserial raises
    ``SerialException``, an ``OSError``; or, from the SDK's ``clearPort`` before each packet,
    pyserial's ``tcflush`` lets ``termios.error`` (EIO), no ``OSError``, escape) is a
    :class:`CommunicationError` naming the port, as a port that cannot be opened is: it had
    reached the user as a Python traceback, and the arm's stop could not tell a lost port from
    any other bug; the ``termios.error`` one as "unexpected error: (5, 'Input/output error')"
    (until 2026-12-02: the emulator's pty closed mid-session, as an unplugged adapter's tty)."""

    def __init__(self, handler: Any, port: Any, device: str = "arm") -> None:
        self._handler = handler
        self._port = port
        self._device = device
        self._interrupted = False

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._handler, name)
        if not callable(attr) or name == "getTxRxResult":
            return attr

        def call(*args: Any, **kwargs: Any) -> Any:
            try:
                if self._interrupted:
                    self._recover()
                return attr(*args, **kwargs)
            except PORT_ERRORS as exc:  # SerialException is an OSError; termios.error not
                self._port.is_using = False
                self._interrupted = True
                raise CommunicationError(
                    self._device,
                    f"the port {self._port.getPortName()!r} failed ({_port_error_text(exc)}): "
                    "check that the "
                    "arm's USB adapter (e.g. a U2D2) is still plugged in and the servos "
                    "powered",
                ) from exc
            except BaseException:
                self._port.is_using = False  # whatever the SDK was doing, it is not any more
                self._interrupted = True
                raise

        return call

    def _recover(self) -> None:
        """Discard what the interrupted exchange left on the line (bounded by a short wait).
        The mark is cleared only once that is done: a further signal during the discard leaves
        it for the next command to do."""
        self._port.is_using = False
        log.debug("port released after an interrupted exchange; discarding a late reply")
        try:
            self._port.setPacketTimeout(11)
            self._handler.rxPacket(self._port, False)
        finally:
            self._port.is_using = False
        self._interrupted = False


class DxlBus:
    """Checked Protocol 2.0 commands over an SDK port (a ``PortHandler`` or a stand-in)."""

    def __init__(
        self,
        port: Any,
        device: str,
        packet_handler: Any | None = None,
        *,
        config: str | None = None,
        power_cycle: str = ct.POWER_CYCLE,
    ) -> None:
        self.port = port
        self.device = device
        #: the rig config the arm was opened from (named in a hardware fault's advice)
        self.config = config
        #: how this chain's servos are power-cycled (the advice's other way to clear a fault)
        self.power_cycle = power_cycle
        #: ``"<command>: <what was lost>"`` for each status packet lost or damaged whose
        #: command, sent once more, then got its answer (counted for the user at the end:
        #: :func:`resends_said`).
        self.resent: list[str] = []
        self.ph = _ReleasingHandler(packet_handler or sdk.PacketHandler(2.0), port, device)
        #: the line speed the port was opened at (named when a servo does not answer)
        self.baudrate: int | None = None
        #: whether anything that changes a servo's state (a write, an action, a reboot) was
        #: ever sent: until then a stop may say nothing was commanded
        self.commanded = False
        #: whether anything that could leave a servo driven was ever sent: any command but a
        #: Torque Enable = 0 or an EEPROM write (which a servo takes only with its torque off,
        #: the limits a first connect writes): until then no servo was driven by this bus
        self.driven = False
        #: ids that have answered on this port since it opened: one of them silent later was
        #: reached at this id and baud rate, so its silence is its cable or power, not those
        self.answered: set[int] = set()
        #: the open port's file (device, inode), to tell it from a descriptor number reused
        self._opened_as: tuple[int, int] | None = None
        #: ids whose status to the last command came after the SDK's window (then the retry's
        #: was not in either): said as a slow link, not as a cable or power lost
        self.late: set[int] = set()
        #: whether the last exchange that timed out got nothing at all through a whole patient
        #: wait (:data:`PATIENT_REPLY_MS`, twice: no status, not even a late one), and no status
        #: has come since: a link where no servo answers (the chain's power or the cable to the
        #: adapter lost). Its next silent servos get the SDK's window, not the slow link's
        #: allowance (:meth:`_exchange`); any status that comes clears it.
        self.link_silent = False

    # -- port -------------------------------------------------------------------------------
    def open(self, baudrate: int) -> None:
        """Open the port at ``baudrate`` and lock it, with SIGINT/SIGTERM held until both are
        done (:func:`signals_deferred`; the stop is acted on as soon as they are).

        Why held: the SDK keeps pyserial's port only once it is open, and pyserial keeps the
        system's descriptor only once ``os.open`` has returned; a stop landing in between (the
        CLI's emergency stop is raised wherever its signal lands) left a descriptor no object
        knew, open until the process ended, and one landing before the lock a port this bus
        had not locked. Opening a serial device is short (non-blocking open, termios calls) but
        can hang (a wedged USB adapter): a second stop ends the hold at once
        (``second_stops``), so Ctrl-C twice or SIGTERM after Ctrl-C still stops it."""
        log.debug("%s: open %s at %d baud", self.device, self.port.getPortName(), baudrate)
        with signals_deferred(second_stops=True):
            try:
                ok = self.port.openPort() and self.port.setBaudRate(baudrate)
            except Exception as exc:  # pyserial raises SerialException/OSError
                # a missing device node: the adapter gone, or back under another name
                missing = _missing(exc)
                note = ports_present_note(self.port.getPortName()) if missing else ""
                # the system's reason alone: pyserial's text names the port twice, in Python's
                # words ("[Errno 2] could not open port P: [Errno 2] No such file …: 'P'")
                why = os.strerror(errno.ENOENT) if missing else str(exc)
                if getattr(exc, "errno", None) == errno.EACCES:
                    # there, but not this user's: the dome's words for it (pyserial's raw
                    # "[Errno 13] could not open port …" had been said, then "check that the
                    # adapter is plugged in", which it is)
                    raise CommunicationError(
                        self.device,
                        f"cannot open port {self.port.getPortName()!r}: "
                        f"{permission_denied_why(self.port.getPortName())}",
                        "open",
                    ) from exc
                raise CommunicationError(
                    self.device,
                    f"cannot open port {self.port.getPortName()!r}: {why}; "
                    f"{note + '; ' if note else ''}check that the "
                    "arm's USB adapter (e.g. a U2D2) is plugged in and that the rig config's "
                    "[arm.dynamixel] port names it",
                    "open",
                ) from exc
            if not ok:
                raise CommunicationError(
                    self.device,
                    f"port {self.port.getPortName()!r} refused baud rate {baudrate}",
                    "open",
                )
            self._lock_exclusively()
            self._opened_as = identity(getattr(self.port, "ser", None))
            self.baudrate = baudrate

    def _lock_exclusively(self) -> None:
        """Hold the port's lock (``flock``, as pyserial's ``exclusive=True`` and the dome's
        transport take it), or close it again and say that another program holds it.

        Why: the SDK opens the port unlocked, so a second ``rti-rig check`` or ``run`` on the
        arm's port while one ran opened it too; the two shared the servos' replies (the second
        failed with "COMM_RX_TIMEOUT … check power, cabling, id and baud rate"), and one that
        got its pings answered would have written position limits (torque off) and goals to
        an arm the other was moving."""
        ser = getattr(self.port, "ser", None)
        fileno = getattr(ser, "fileno", None)
        if fileno is None:
            return  # an in-process stand-in (no file), or a platform without one
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not POSIX
            return
        try:
            fcntl.flock(fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            name = self.port.getPortName()
            self.port.closePort()
            raise CommunicationError(
                self.device,
                f"port {name!r} is locked by another program (another rti-rig check or run "
                "on this arm): nothing was sent; let it finish or stop it, then try again",
                "open",
            ) from None
        except OSError:
            return  # a device that cannot be locked (flock unsupported): as before

    def close(self) -> None:
        """Release the port (its descriptor, and with it the lock); safe twice.

        A stop raised inside the SDK's close (pyserial's, underneath) had left the descriptor
        open and locked, the SDK still counting the port open: a second ``rti-rig`` was told
        the port "is locked by another program" until this process ended, and a later close
        landing after pyserial's own ``os.close`` closed whatever file had since been given
        that number. The close is finished before the stop goes on, as the dome's transport
        finishes its own (:func:`finish_close`)."""
        self.answered.clear()
        self.link_silent = False
        if not getattr(self.port, "is_open", False):
            return
        ser = getattr(self.port, "ser", None)
        try:
            self.port.closePort()
        except BaseException:
            if isinstance(ser, serial.SerialBase):
                finish_close(ser, self._opened_as)
            self.port.is_open = False
            raise

    # -- checks -----------------------------------------------------------------------------
    def _check(self, result: int, error: int, dxl_id: int, command: str, alert: bool = True):
        # the mark is this command's alone (set by its retry just before): a later command
        # that is not retried (a reboot, a ping sent once) must not inherit it, or a servo
        # gone since would be said to be there, only slow
        late = dxl_id in self.late
        self.late.discard(dxl_id)
        if result != sdk.COMM_RX_TIMEOUT:
            self.link_silent = False  # a status came: the link carries answers
        if result != sdk.COMM_SUCCESS:
            at = f" at {self.baudrate} baud" if self.baudrate else ""
            if result == sdk.COMM_RX_TIMEOUT and late:
                raise CommunicationError(
                    self.device,
                    f"{comm_text(self.ph, result)}{at}: its status came on "
                    f"{self.port.getPortName()!r}, but late (after the SDK's reply window), and "
                    f"the retry's did not come within {PATIENT_REPLY_MS:g} ms: the servo is "
                    "there, its answers are slow to reach this computer, a slow USB-serial "
                    f"adapter{_latency_note(self.port.getPortName())} or a computer too busy to "
                    "read the port in time; close what loads it and run the command again",
                    command,
                    dxl_id,
                    result,
                )
            if result == sdk.COMM_RX_TIMEOUT and dxl_id in self.answered:
                # it answered at this id and rate before: "check id and baud rate" had sent a
                # user whose cable came out mid-session to a config that was right
                raise CommunicationError(
                    self.device,
                    f"{comm_text(self.ph, result)}{at}: it had answered on "
                    f"{self.port.getPortName()!r} and has stopped answering: its cable, "
                    "the chain of cables to it, or the servos' power supply was lost; check "
                    "them (the id and baud rate were right)",
                    command,
                    dxl_id,
                    result,
                )
            raise CommunicationError(
                self.device,
                f"{comm_text(self.ph, result)}{at} (check power, cabling, id and baud rate: "
                "X-series servos ship at 57600)",
                command,
                dxl_id,
                result,
            )
        self.answered.add(dxl_id)
        if error & 0x7F:
            raise ServoStatusError(
                self.device, dxl_id, error, command, f"servo answered {p2.describe_error(error)}"
            )
        if alert and error & p2.ERR_ALERT:
            raise self.hardware_fault(dxl_id, command)

    def hardware_fault(
        self, dxl_id: int, command: str, status: int | None = None
    ) -> HardwareFaultError:
        """The fault a servo's Alert flag signals, with its torque as read, not as assumed.

        Torque Enable is read because a servo drops torque only for the faults its Shutdown
        register selects, and the factory setting differs per model (ROBOTIS e-manual, Shutdown
        Initial Value): 0x34 on the XL430/XM430/XH430/XM540, where an input-voltage error
        leaves the joint driven, 0x35 on the XL330-M288, where it switches torque off. A torque
        that cannot be read is reported as unknown. For an input-voltage error the supply and
        the servo's own limits are read too (best effort): they differ per model (an XL330 is
        a 3.5..7.0 V servo, an XL430 6.0..14.0 V, an XM430 9.5..16.0 V)."""
        if status is None:
            status = self.read(dxl_id, ct.HARDWARE_ERROR_STATUS, check_alert=False)
        try:
            torque_on: bool | None = bool(self.read(dxl_id, ct.TORQUE_ENABLE, check_alert=False))
        except DynamixelError:
            torque_on = None
        voltage: tuple[int, int, int] | None = None
        if status & ct.HardwareFault.INPUT_VOLTAGE:
            try:
                regs = (ct.PRESENT_INPUT_VOLTAGE, ct.MIN_VOLTAGE_LIMIT, ct.MAX_VOLTAGE_LIMIT)
                voltage = tuple(  # type: ignore[assignment]
                    self.read(dxl_id, reg, check_alert=False) for reg in regs
                )
            except DynamixelError:
                voltage = None
        return HardwareFaultError(
            self.device,
            dxl_id,
            status,
            command,
            torque_on,
            voltage,
            config=self.config,
            power_cycle=self.power_cycle,
        )

    #: Results that mean the status packet was lost or damaged (not that the servo refused).
    RETRYABLE = (sdk.COMM_RX_TIMEOUT, sdk.COMM_RX_CORRUPT)

    def _exchange(self, call, what: str, dxl_id: int):  # type: ignore[no-untyped-def]
        """Run an idempotent ``call`` (returning ``(..., result, error)``), retried once if
        its status packet was lost or corrupt: reading twice changes nothing on the servo, and
        writing a register's value twice leaves it as writing it once does (Goal Position
        included: the servo plans its profile to the same goal from where it is)."""
        self.late.discard(dxl_id)
        reply = call()
        if reply[-2] in self.RETRYABLE:
            # never a warning the command line would print raw beside its progress bar: a
            # retry that got its answer is counted at the end (:attr:`resent`), one that did
            # not raises the error the command says
            first = reply[-2]
            log.info(
                "%s: id %d %s: %s; retrying once",
                self.device,
                dxl_id,
                what,
                comm_text(self.ph, reply[-2]),
            )
            late = False
            if reply[-2] == sdk.COMM_RX_TIMEOUT and self.link_silent:
                reply, late = self._retry_on_silent_link(call)
            elif reply[-2] == sdk.COMM_RX_TIMEOUT:
                # a reply that was only late must not be read as the answer to a later command;
                # one that comes is the sign of a slow link, not of a servo gone
                late = self.drain_reply(PATIENT_REPLY_MS)
                with self._patient():
                    reply = call()
                # nothing at all in a whole patient wait, twice: no slow link, a silent one
                self.link_silent = not late and reply[-2] == sdk.COMM_RX_TIMEOUT
            else:
                reply = call()
            if late and reply[-2] == sdk.COMM_RX_TIMEOUT:
                self.late.add(dxl_id)
            if reply[-2] == sdk.COMM_SUCCESS:
                lost = (
                    "damaged status packet"
                    if first != sdk.COMM_RX_TIMEOUT
                    else "late status packet"
                    if late
                    else "no status packet"
                )
                self.resent.append(f"id {dxl_id} {what}: {lost}")
        return reply

    def _retry_on_silent_link(self, call):  # type: ignore[no-untyped-def]
        """The retry of an exchange that timed out on a :attr:`link_silent` link: ``(reply,
        late)``, within the SDK's own windows, not the slow link's allowance.

        Why: when the chain loses power, every servo is silent, and each had cost the
        allowance (about 1 s: the wait for a late status, then a patient retry) before its
        error: a stop and a close reading N servos took seconds on an arm whose lamp may be
        lit, before the user read what had happened. The allowance is for a link whose
        statuses come late; this one has just delivered nothing at all through a whole
        patient wait. Should a status come after all (a slow link on which one servo alone
        is gone), the allowance is back: after a late status in the short drain the retry is
        waited for patiently, as before, and a retry that is answered is followed by the
        patient drain of the status its first try may still owe (never read as a later
        command's answer)."""
        if self.drain_reply():  # the first try's status, late: the link lives, only slow
            self.link_silent = False
            with self._patient():
                return call(), True
        reply = call()
        if reply[-2] != sdk.COMM_RX_TIMEOUT:
            self.link_silent = False
            self.drain_reply(PATIENT_REPLY_MS)  # the first try's status, if it is on its way
        return reply, False

    @contextlib.contextmanager
    def _patient(self) -> Iterator[None]:
        """The SDK's reply windows set while inside last at least :data:`PATIENT_REPLY_MS`
        (its exchanges set their own window, so the port's setter is wrapped)."""
        port = self.port
        own = port.setPacketTimeout
        shadowed = vars(port).get("setPacketTimeout")  # a stand-in's own, put back after

        def patient(packet_length: int) -> None:
            own(packet_length)
            port.packet_timeout = max(float(getattr(port, "packet_timeout", 0)), PATIENT_REPLY_MS)

        port.setPacketTimeout = patient
        try:
            yield
        finally:
            if shadowed is None:
                del port.setPacketTimeout
            else:
                port.setPacketTimeout = shadowed

    # -- commands ---------------------------------------------------------------------------
    def ping(self, dxl_id: int, *, once: bool = False) -> int:
        """Model number of servo ``dxl_id`` (raises if it does not answer).

        ``once``: no retry (nor its warning) after a lost reply, for a caller that pings in a
        loop of its own (waiting for a rebooted servo, silent while it restarts: each ping had
        warned "retrying once", nine lines for one reboot)."""
        if once:
            model, result, error = self.ph.ping(self.port, dxl_id)
            if result == sdk.COMM_RX_TIMEOUT:
                self.drain_reply()  # a late reply must not answer a later command
        else:
            model, result, error = self._exchange(
                lambda: self.ph.ping(self.port, dxl_id), "ping", dxl_id
            )
        log.debug("%s: ping %d -> model %s (%d, %d)", self.device, dxl_id, model, result, error)
        self._check(result, error, dxl_id, "ping", alert=False)
        return int(model)

    def scan(self) -> dict[int, int] | None:
        """``{id: model number}`` of every servo answering a broadcast Ping at this baud rate
        (``None``: the scan itself failed). Read-only, for naming what is on the bus when a
        configured servo does not answer; answers that arrive damaged are left out."""
        try:
            found, result = self.ph.broadcastPing(self.port)
        except DynamixelError:
            return None
        log.debug("%s: broadcast ping -> %s (%d)", self.device, found, result)
        if result not in (sdk.COMM_SUCCESS, sdk.COMM_RX_TIMEOUT, sdk.COMM_RX_CORRUPT):
            return None
        return {int(i): int(v[0]) for i, v in (found or {}).items()}

    def scan_rates(
        self, rates: Iterable[int], tried: list[int] | None = None
    ) -> tuple[int, dict[int, int]] | None:
        """The first of ``rates`` at which servos answer a broadcast Ping, with ``{id: model
        number}``; None if none answers at any (or the adapter takes none of them). Each rate
        the port was set to is appended to ``tried`` (one the adapter refuses is not). The
        port is set back to the rate it was opened at, and locked again, whatever happens.

        Read-only (a Ping changes nothing on a servo), as Dynamixel Wizard 2.0's scan: for
        naming the rate a bus silent at the configured one answers at (X-series servos ship
        at 57600, and a user may have set another, ROBOTIS e-manual, Baud Rate (8)). A
        broadcast Ping waits its whole window (about 0.8 s at 1 Mbps, 4.4 s at 9600 baud), so
        the rates are tried in the order given and the scan stops at the first that answers."""
        configured = self.baudrate
        if configured is None:
            return None
        try:
            for rate in rates:
                if rate == configured:
                    continue
                try:
                    # the SDK reopens the port (see open)
                    with signals_deferred(second_stops=True):
                        if not self.port.setBaudRate(rate):
                            continue
                except Exception:  # an adapter (or pty) that cannot run at this rate
                    continue
                if tried is not None:
                    tried.append(rate)
                found = self.scan()
                if found:
                    return rate, found
            return None
        finally:
            try:
                # the SDK reopens the port (see open): lock it again
                with signals_deferred(second_stops=True):
                    self.port.setBaudRate(configured)
                    self._lock_exclusively()
            except Exception as exc:  # the caller's error says what the bus gave
                log.info(  # the caller's error is said; this is its detail
                    "%s: could not set the port back to %d baud: %s", self.device, configured, exc
                )

    def read(self, dxl_id: int, reg: ct.Register, check_alert: bool = True) -> int:
        command = f"read {reg.name}"
        fn = {1: self.ph.read1ByteTxRx, 2: self.ph.read2ByteTxRx, 4: self.ph.read4ByteTxRx}
        value, result, error = self._exchange(
            lambda: fn[reg.size](self.port, dxl_id, reg.address), command, dxl_id
        )
        log.debug("%s: id %d %s -> %s (%d, %d)", self.device, dxl_id, command, value, result, error)
        self._check(result, error, dxl_id, command, alert=check_alert)
        return p2.to_signed(value, reg.size) if reg.signed else int(value)

    def read_block(self, dxl_id: int, address: int, length: int) -> tuple[bytes, int]:
        """Raw bytes of ``length`` registers from ``address`` and the status ERR byte.

        Hardware alerts are *not* raised here; the caller decides (it may want the data)."""
        command = f"read {_span_name(address, length)}"
        data, result, error = self._exchange(
            lambda: self.ph.readTxRx(self.port, dxl_id, address, length), command, dxl_id
        )
        log.debug(
            "%s: id %d read %d+%d -> %s (%d, %d)",
            self.device,
            dxl_id,
            address,
            length,
            bytes(data or b"").hex(),
            result,
            error,
        )
        self._check(result, error, dxl_id, command, alert=False)
        if len(data) != length:
            raise CommunicationError(
                self.device, f"short reply: {len(data)} of {length} bytes", command, dxl_id
            )
        return bytes(data), int(error)

    def _commanding(self, reg: ct.Register | None = None, value: int | None = None) -> None:
        """Record a command going out (:attr:`commanded`, :attr:`driven`)."""
        self.commanded = True
        if reg is None or not (reg.eeprom or (reg is ct.TORQUE_ENABLE and value == 0)):
            self.driven = True

    def write(self, dxl_id: int, reg: ct.Register, value: int, check_alert: bool = True) -> None:
        self._commanding(reg, value)
        command = f"write {reg.name} = {value}"
        raw = value & ((1 << (8 * reg.size)) - 1)
        fn = {1: self.ph.write1ByteTxRx, 2: self.ph.write2ByteTxRx, 4: self.ph.write4ByteTxRx}
        # retried once when its status is lost or damaged: one lost reply to a lamp or goal
        # write had ended the session, though the servo had most likely acted on it
        result, error = self._exchange(
            lambda: fn[reg.size](self.port, dxl_id, reg.address, raw), command, dxl_id
        )
        log.debug("%s: id %d %s (%d, %d)", self.device, dxl_id, command, result, error)
        self._check(result, error, dxl_id, command, alert=check_alert)

    def write_no_wait(self, dxl_id: int, reg: ct.Register, value: int) -> None:
        """Unicast write without waiting for success, *then drain the reply* it provokes.

        Without the drain, the status the servo sends back is read as the answer to the next
        command (SDK pitfall; ROBOTIS PR #646)."""
        self._commanding(reg, value)
        raw = value & ((1 << (8 * reg.size)) - 1)
        data = list(raw.to_bytes(reg.size, "little"))
        result = self.ph.writeTxOnly(self.port, dxl_id, reg.address, reg.size, data)
        log.debug(
            "%s: id %d write-no-wait %s = %d (%d)", self.device, dxl_id, reg.name, value, result
        )
        if result != sdk.COMM_SUCCESS:
            raise CommunicationError(
                self.device, comm_text(self.ph, result), f"write {reg.name}", dxl_id, result
            )
        self.drain_reply()

    def drain_reply(self, wait_ms: float | None = None) -> bool:
        """Read and discard one pending status packet, if any (bounded by the SDK timeout, or
        ``wait_ms``); whether any byte of one came."""
        if wait_ms is None:
            self.port.setPacketTimeout(11)
        else:
            self.port.setPacketTimeoutMillis(wait_ms)
        return self.ph.rxPacket(self.port, False)[1] != sdk.COMM_RX_TIMEOUT

    def sync_write(self, reg: ct.Register, values: Mapping[int, int]) -> None:
        """Same register on several servos in one broadcast packet (no reply to wait for)."""
        self._commanding()
        group = sdk.GroupSyncWrite(self.port, self.ph, reg.address, reg.size)
        for dxl_id, value in values.items():
            raw = int(value) & ((1 << (8 * reg.size)) - 1)
            group.addParam(dxl_id, list(raw.to_bytes(reg.size, "little")))
        result = group.txPacket()
        log.debug("%s: sync write %s %s (%d)", self.device, reg.name, dict(values), result)
        if result != sdk.COMM_SUCCESS:
            raise CommunicationError(
                self.device,
                comm_text(self.ph, result),
                f"sync write {reg.name} {dict(values)}",
                result=result,
            )

    def broadcast_write(self, reg: ct.Register, value: int) -> None:
        """Write to every servo at once; broadcast writes get no status, so none is left over."""
        self._commanding(reg, value)
        raw = value & ((1 << (8 * reg.size)) - 1)
        data = list(raw.to_bytes(reg.size, "little"))
        result = self.ph.writeTxOnly(self.port, p2.BROADCAST_ID, reg.address, reg.size, data)
        log.debug("%s: broadcast write %s = %d (%d)", self.device, reg.name, value, result)
        if result != sdk.COMM_SUCCESS:
            raise CommunicationError(
                self.device,
                comm_text(self.ph, result),
                f"broadcast write {reg.name}",
                result=result,
            )

    def action(self) -> None:
        """Action to the broadcast id: unicast Action leaves a stale reply (SDK pitfall)."""
        self._commanding()
        result = self.ph.action(self.port, p2.BROADCAST_ID)
        if result != sdk.COMM_SUCCESS:
            raise CommunicationError(
                self.device, comm_text(self.ph, result), "action", result=result
            )

    def reboot(self, dxl_id: int) -> None:
        self._commanding()
        result, error = self.ph.reboot(self.port, dxl_id)
        log.debug("%s: reboot %d (%d, %d)", self.device, dxl_id, result, error)
        self._check(result, error, dxl_id, "reboot", alert=False)


def _port_error_text(exc: BaseException) -> str:
    """A failed port's reason in the system's words: a ``termios.error`` is a bare
    ``(errno, text)`` tuple, said as an ``OSError`` is (``[Errno 5] Input/output error``)."""
    if isinstance(exc, OSError) or len(exc.args) != 2 or not isinstance(exc.args[0], int):
        return str(exc)
    return f"[Errno {exc.args[0]}] {exc.args[1]}"


def _missing(exc: BaseException) -> bool:
    """Whether an open failed because the device node is not there (ENOENT): pyserial's
    ``SerialException`` carries the system's errno, a plain ``OSError`` its own."""
    return getattr(exc, "errno", None) == errno.ENOENT


def _span_name(address: int, length: int) -> str:
    """``Moving..Present Position`` for a block read of the control table, as an error names
    the command (it had said ``read 122+14``, which a user cannot look up); the addresses
    when no register starts and ends the span."""
    items = [r for r in vars(ct).values() if isinstance(r, ct.Register)]
    first = next((r for r in items if r.address == address), None)
    last = next((r for r in items if r.address + r.size == address + length), None)
    if first is None or last is None:
        return f"{address}+{length}"
    return first.name if first is last else f"{first.name}..{last.name}"


#: Where Linux shows each USB-serial adapter's settings (its ``latency_timer`` among them).
USB_SERIAL_DEVICES = "/sys/bus/usb-serial/devices"


def _latency_note(port: str, devices: str = USB_SERIAL_DEVICES) -> str:
    """`` (set its latency timer to 1 ms: COMMAND)`` for a USB-serial adapter whose latency
    timer Linux shows (an FTDI's, 16 ms by default, which the SDK's window just covers), with
    the real file of ``port``; "" where there is none (the command would be a template)."""
    try:
        name = os.path.basename(os.path.realpath(port))
    except (OSError, ValueError):
        return ""
    timer = os.path.join(devices, name, "latency_timer")
    if not name or not os.path.isfile(timer):
        return ""
    return f" (set its latency timer to 1 ms: echo 1 | sudo tee {shell_word(timer)})"


def _count_said(n: int, lost: str) -> str:
    """``n`` statuses ``lost`` the way a :attr:`DxlBus.resent` entry says ("no status packet",
    "late status packet", "damaged status packet") as counted words: "1 lost status packet",
    "109 late status packets".

    Why: the count had been put before the entry's own words, so 109 statuses that came late
    were said as "109 late status packet", and a missing one as "1 no status packet"."""
    kind = "lost status packet" if lost == "no status packet" else lost
    return f"{n} {kind}{'s' if n != 1 else ''}"


def resends_said(resent: list[str]) -> str | None:
    """One line for the commands sent once more after their status packet was lost or damaged
    and then answered, counted by what was lost; None when there were none.

    Why: each had been a raw log record ("arm: id 2 read Velocity Limit: COMM_RX_TIMEOUT: …;
    retrying once") printed on stderr in the middle of the progress bar. A retry that got its
    answer changes nothing the user must do, but a count says the bus is not clean (a cable,
    a connector, the termination to look at)."""
    if not resent:
        return None
    lost = [entry.rsplit(": ", 1)[-1] for entry in resent]
    counts = ", ".join(_count_said(lost.count(x), x) for x in dict.fromkeys(lost))
    n = len(resent)
    how = "lost, late or damaged" if "late status packet" in lost else "lost or damaged"
    return (
        f"The arm's servos were asked again {n} time{'s' if n != 1 else ''} after a status "
        f"packet was {how} ({counts}); each then answered."
    )
