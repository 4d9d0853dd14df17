"""Serve a byte-level device emulator on a pseudo-terminal, so real pyserial talks to it.

A thread owns the master side of an ``os.openpty()`` pair; the host opens the slave through a
stable symlink (like ``/dev/serial/by-id/...``) with ordinary pyserial. The helper emulates what
matters about a USB serial board:

* **auto-reset on open**: whenever the slave gets opened, the device's ``on_port_opened()``
  runs, so an Arduino-like board reboots and sends its banner. On Linux every open is seen
  (inotify on the slave's device node), also a close and reopen within microseconds, as a
  program that probes a port several times does: the master's hang-up, the only sign
  elsewhere, is missed when the reopen comes before the server thread polls, and the board then
  did not reset where a real one does (DTR drops on close and rises on open);
* **USB drop**: when the device asks for it (``take_disconnect()``), the pty is torn down (the
  host's next read or write fails as on a real unplug) and a fresh one appears behind the same
  symlink after the requested time, so the host can reconnect by path;
* **timed replies**: outputs carry due times, so late replies really arrive late.

Shutdown is bounded: the thread polls with a short timeout and is joined with a timeout.
"""

from __future__ import annotations

import contextlib
import ctypes
import fcntl
import os
import select
import shutil
import signal
import struct
import sys
import tempfile
import termios
import threading
import time
import tty
from abc import abstractmethod
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, runtime_checkable

#: inotify event bits (``<sys/inotify.h>``).
_IN_CLOSE_WRITE, _IN_CLOSE_NOWRITE, _IN_OPEN = 0x08, 0x10, 0x20
_IN_EVENT = struct.Struct("iIII")  # wd, mask, cookie, len (a name of len bytes follows)


class _OpenWatch:
    """Opens and closes of one device node, seen through inotify (Linux); see the module doc.

    ``available`` is False where inotify is not (another OS, a libc without it): the server
    then falls back on the master's hang-up, which misses a quick close and reopen.
    """

    def __init__(self) -> None:
        self.fd = -1
        self.wd = -1
        self._libc = None
        self._failed = False  # a node could not be watched: fall back on the hang-up
        if not sys.platform.startswith("linux"):
            return
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            fd = libc.inotify_init1(os.O_NONBLOCK | os.O_CLOEXEC)
        except (OSError, AttributeError):
            return
        if fd >= 0:
            self._libc, self.fd = libc, fd

    @property
    def available(self) -> bool:
        return self.fd >= 0 and not self._failed

    def watch(self, path: str) -> None:
        """Watch ``path`` from now on (events of an earlier node are ignored)."""
        if self._libc is None:
            return
        mask = _IN_OPEN | _IN_CLOSE_WRITE | _IN_CLOSE_NOWRITE
        self.wd = self._libc.inotify_add_watch(self.fd, os.fsencode(path), mask)
        self._failed = self.wd < 0

    def events(self) -> list[bool]:
        """The opens (True) and closes (False) of the watched node since the last call.

        Read whenever the descriptor is open, also after a failed watch: events left unread
        would keep it ready, and the server's poll would spin."""
        if self.fd < 0:
            return []
        try:
            data = os.read(self.fd, 4096)
        except (BlockingIOError, InterruptedError):
            return []
        out = []
        offset = 0
        while offset + _IN_EVENT.size <= len(data):
            wd, mask, _cookie, length = _IN_EVENT.unpack_from(data, offset)
            offset += _IN_EVENT.size + length
            if wd != self.wd:
                continue  # a node replaced after a USB drop
            if mask & _IN_OPEN:
                out.append(True)
            if mask & (_IN_CLOSE_WRITE | _IN_CLOSE_NOWRITE):
                out.append(False)
        return out

    def close(self) -> None:
        if self.fd >= 0:
            os.close(self.fd)
            self.fd = -1


class TimedOutput(Protocol):
    due_s: float
    data: bytes


class PtyDevice(Protocol):
    """A device emulator whose outputs are timed on ``time.monotonic`` (a ``SystemClock``)."""

    def on_port_opened(self) -> list[TimedOutput]: ...

    def receive(self, data: bytes) -> list[TimedOutput]: ...

    def take_disconnect(self) -> float | None: ...

    def on_port_closed(self) -> None:
        """The host closed the port (its DTR dropped): a board that acts on it (an ATmega32u4
        touched at 1200 baud jumps to its bootloader) says so here; declared, where the server
        had probed for it with ``getattr`` (a misspelt name went unheard)."""


@runtime_checkable
class HostBaudDevice(Protocol):
    """A :class:`PtyDevice` that sees the speed the host set its UART to (``host_baud``, set
    by the server on each pass; None until then): behind a USB-serial chip two UARTs at
    different rates read garbage, and a native-USB board is touched at 1200 baud.

    Declared by the concrete class (``class Board(HostBaudDevice, TickingDevice)``), where
    the server had probed for the name with ``hasattr``: a device that misspelt it was never
    told the host's rate."""

    host_baud: int | None


@runtime_checkable
class TickingDevice(Protocol):
    """A :class:`PtyDevice` that acts on its own time (a sketch's timers, a watchdog, a
    self-timed LED going dark): ``tick`` is called on each pass while the port is open and
    returns what it sent meanwhile. Abstract: a class that declares it and renames the method
    cannot be built (the server had probed for it with ``getattr``, a misspelt one never
    ran)."""

    @abstractmethod
    def tick(self) -> list[TimedOutput]: ...


@dataclass
class PtyLink:
    """A running pty server: open ``port`` with pyserial; ``stop()`` to end (also on exit)."""

    port: str
    device: PtyDevice
    _stop: threading.Event
    _thread: threading.Thread
    errors: list[BaseException]

    _server: _Server | None = None

    @property
    def alive(self) -> bool:
        return self._thread.is_alive()

    def wait_delivered(self, timeout_s: float = 5.0) -> bool:
        """Wait until the device has been handed every byte the host wrote (bounded).

        A real UART delivers a byte within its wire time; a pty's server thread may lag behind
        under CPU load. A simulated camera calls this before it looks at the emulated light, so
        the dry run sees what the board would have done by then, whatever the load.
        """
        server = self._server
        if server is None:
            return True
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            if server.master < 0:
                return False
            try:
                pending = struct.unpack(
                    "i", fcntl.ioctl(server.master, termios.FIONREAD, b"\0" * 4)
                )[0]
            except OSError:
                return False
            if pending == 0:
                seen = server.iterations
                while server.iterations < seen + 2 and time.monotonic() < end:
                    time.sleep(0.001)
                return server.iterations >= seen + 2
            time.sleep(0.001)
        return False

    def stop(self, timeout_s: float = 2.0) -> None:
        self._stop.set()
        self._thread.join(timeout_s)
        if self._thread.is_alive():
            raise RuntimeError(f"pty server for {self.port} did not stop within {timeout_s} s")


class _Server:
    def __init__(self, device: PtyDevice, link_path: Path, stop: threading.Event) -> None:
        self.device = device
        # what the device declares, decided once: a runtime-checkable protocol's isinstance
        # walks its members each time; measured on a Board (timeit, Python 3.11, a loaded
        # 2-core machine), the two checks took 36-52 us a pass together (one 11-28 us),
        # against 0.3-0.5 us for the hasattr + getattr pair they replaced, and the loop below
        # passes every 10 ms or sooner
        self.host_baud_device = device if isinstance(device, HostBaudDevice) else None
        self.ticking_device = device if isinstance(device, TickingDevice) else None
        self.link_path = link_path
        self.stop = stop
        self.master = -1
        self.opened = False
        self.pending: list[TimedOutput] = []
        self.errors: list[BaseException] = []
        self.iterations = 0  # loops run (wait_delivered waits for the next ones)
        self.watch = _OpenWatch()
        self.openers = 0  # programs holding the slave open (counted when ``watch`` works)

    def new_pty(self) -> None:
        master, slave = os.openpty()
        tty.setraw(slave)
        target = os.ttyname(slave)
        os.close(slave)  # keep no slave fd: a hang-up on the master then means "nobody opened it"
        tmp = self.link_path.with_suffix(".new")
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        tmp.symlink_to(target)
        tmp.replace(self.link_path)
        self.watch.watch(target)  # after the slave fd above is closed: only the host's opens
        old, self.master = self.master, master
        self.opened = False
        self.openers = 0
        self.pending.clear()
        if old >= 0:
            os.close(old)

    def run(self) -> None:
        try:
            self._loop()
            self._reset_by_late_opens()
        except BaseException as exc:  # reported to the test through PtyLink.errors
            self.errors.append(exc)
        finally:
            if self.master >= 0:
                os.close(self.master)
                self.master = -1
            self.watch.close()

    def _loop(self) -> None:
        poller = select.poll()
        registered = -1
        while not self.stop.is_set():
            self.iterations += 1
            if registered != self.master:
                if registered >= 0:
                    with contextlib.suppress(KeyError, ValueError):
                        poller.unregister(registered)
                poller.register(self.master, select.POLLIN)
                registered = self.master
                if self.watch.fd >= 0:
                    with contextlib.suppress(KeyError, ValueError):
                        poller.register(self.watch.fd, select.POLLIN)
            events = poller.poll(self._poll_ms())
            hup = any(fd == self.master and ev & select.POLLHUP for fd, ev in events)
            seen = self.watch.events()
            if self.watch.available:
                # every open is a reset, however soon after a close (see the module doc); the
                # events were queued by the host's open() before it could write anything
                for opened in seen:
                    if opened:
                        self.openers += 1
                        if self.openers == 1:
                            self.opened = True
                            self.pending.clear()  # a close unseen by the hang-up: output lost
                            self.pending += self.device.on_port_opened()
                    else:
                        self.openers = max(0, self.openers - 1)
                        if self.openers == 0:
                            self.opened = False
                            self.pending.clear()
                            self._closed()
            if hup:
                if self.opened and not self.watch.available:
                    self.opened = False
                    self.pending.clear()  # nobody listens: output is lost, as on a real board
                    self._closed()
                time.sleep(0.002)
            elif not self.opened and not self.watch.available:
                self.opened = True
                self.pending += self.device.on_port_opened()
            if any(fd == self.master and ev & select.POLLIN for fd, ev in events) and not hup:
                try:
                    data = os.read(self.master, 4096)
                except OSError:
                    data = b""
                if data:
                    self.pending += self.device.receive(data)
            if self.host_baud_device is not None:  # the host's UART speed, as it sees it
                self.host_baud_device.host_baud = host_baud(self.master)
            if self.ticking_device is not None and self.opened:
                self.pending += self.ticking_device.tick()
            down = self.device.take_disconnect()
            if down is not None:
                self._unplug(down)
                continue
            self._flush_due()

    def _closed(self) -> None:
        """The host closed the port (DTR dropped): told to a device that acts on it (an
        ATmega32u4 set to 1200 baud jumps to its bootloader)."""
        self.device.on_port_closed()

    def _reset_by_late_opens(self) -> None:
        """An open of the port the loop had not read when the server was asked to stop still
        resets the board (its DTR rose as the port opened): a host that opened and closed the
        port just before its rig closed (a stop inside pyserial's open) had left the emulated
        Nab board dark where the real one, reset, boots with every LED lit."""
        if self.watch.available and any(self.watch.events()):
            self.device.on_port_opened()

    def _poll_ms(self) -> int:
        if not self.pending:
            return 10
        wait = min(o.due_s for o in self.pending) - time.monotonic()
        return max(0, min(10, int(wait * 1000) + 1))

    def _flush_due(self) -> None:
        if not self.pending or not self.opened:
            return
        now = time.monotonic()
        due = sorted((o for o in self.pending if o.due_s <= now), key=lambda o: o.due_s)
        if not due:
            return
        self.pending = [o for o in self.pending if o.due_s > now]
        data = b"".join(o.data for o in due)
        with contextlib.suppress(OSError):
            os.write(self.master, data)

    def _unplug(self, down_s: float) -> None:
        """Close the pty (the host sees EIO), then offer a new one after ``down_s``.

        With ``down_s <= 0`` the new pty is behind the symlink before the old one closes, so a
        host that reconnects as soon as it notices the drop finds the device back at once.
        """
        if down_s <= 0:
            self.new_pty()
            return
        with contextlib.suppress(FileNotFoundError):
            self.link_path.unlink()
        os.close(self.master)
        self.master = -1
        self.pending.clear()
        self.stop.wait(max(0.0, down_s))
        if not self.stop.is_set():
            self.new_pty()


_SPEEDS = {
    getattr(termios, f"B{n}"): n
    for n in (
        *(300, 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400),
        *(460800, 500000, 576000, 921600, 1000000, 1152000, 2000000, 2500000, 3000000),
        *(3500000, 4000000),
    )
    if hasattr(termios, f"B{n}")
}


def host_baud(master: int) -> int | None:
    """The baud rate the host set on the slave (a pty pair shares its termios)."""
    try:
        return _SPEEDS.get(termios.tcgetattr(master)[4])
    except (termios.error, OSError):
        return None


#: The temporary folders the emulated ports live in: ``<tempdir>/rti-rig-pty-XXXX``.
PTY_FOLDER_PREFIX = "rti-rig-pty-"
#: The file in such a folder naming the process that serves it:
#: ``<pid> <start time> <pid namespace>``.
PTY_OWNER_FILE = "owner"


def _pid_namespace() -> str:
    """This process's pid namespace (``pid:[4026531836]``), or "" where it cannot be read: a
    pid means a process only within its namespace."""
    try:
        return os.readlink("/proc/self/ns/pid")
    except OSError:
        return ""


def owner_line() -> str:
    """What this process writes in the owner file of a pty folder it serves."""
    pid = os.getpid()
    return f"{pid} {_start_time(pid)} {_pid_namespace()}".rstrip() + "\n"


def _start_time(pid: int) -> str:
    """The process's start time (clock ticks since boot, ``/proc/<pid>/stat``'s field 22), or
    "" where it cannot be read: with the pid it names one process, not a later one given the
    same number."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return ""
    # the command name (field 2) is in parentheses and may hold spaces: count after it
    return stat.rpartition(")")[2].split()[19]


def _owner_alive(owner: str) -> bool:
    """Whether the process an owner file names (``<pid> <start time> <pid namespace>``) is
    still running; True where that cannot be told.

    A process of another pid namespace (a container sharing this temporary directory) is
    never taken for dead: its pid means another process here, or none, while it serves on."""
    pid_text, started, namespace = [*owner.split(), "", "", ""][:3]
    try:
        pid = int(pid_text)
    except ValueError:
        return True  # unreadable: never taken for dead
    if pid <= 0:
        return True
    if namespace and namespace != _pid_namespace():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's live process
    return not started or _start_time(pid) in ("", started)


def remove_stale_pty_folders(root: Path | None = None) -> list[Path]:
    """Remove the emulated-port folders (``rti-rig-pty-*`` under ``root``, the temporary
    directory by default) whose serving process is gone; the folders removed.

    Why: an emulator ends by removing its folder, but one killed outright (SIGKILL, an
    out-of-memory kill, a test's timeout) cannot, and its folder stayed in /tmp for ever,
    one more for each. Only a folder of this user's with an owner file naming a process that
    no longer runs (its pid gone, or reused by a process started later) is removed: a live
    emulator's never, nor a folder whose owner cannot be told (one made before owner files)."""
    base = Path(tempfile.gettempdir()) if root is None else root
    removed: list[Path] = []
    try:
        candidates = list(base.glob(f"{PTY_FOLDER_PREFIX}*"))
    except OSError:
        return removed
    for folder in candidates:
        try:
            if folder.is_symlink() or not folder.is_dir() or folder.stat().st_uid != os.getuid():
                continue
            owner = (folder / PTY_OWNER_FILE).read_text()
        except OSError:
            continue  # no owner file (or unreadable): its owner cannot be told
        if _owner_alive(owner):
            continue
        shutil.rmtree(folder, ignore_errors=True)  # symlinks inside are removed, not followed
        if not folder.exists():
            removed.append(folder)
    return removed


@contextlib.contextmanager
def serve_on_pty(device: PtyDevice, name: str = "dome") -> Iterator[PtyLink]:
    """Serve ``device`` on a pty; yields a :class:`PtyLink` whose ``port`` pyserial can open.

    The folder of its port names this process as its owner, and folders that emulators killed
    outright left behind are removed first (:func:`remove_stale_pty_folders`)."""
    remove_stale_pty_folders()
    folder = Path(tempfile.mkdtemp(prefix=PTY_FOLDER_PREFIX))
    # written whole, then named: another emulator's clean-up reading it half-written ("12" of
    # "12345 …") could take a live folder for a dead process's
    (folder / f"{PTY_OWNER_FILE}.new").write_text(owner_line())
    os.replace(folder / f"{PTY_OWNER_FILE}.new", folder / PTY_OWNER_FILE)
    link_path = folder / f"tty-{name}"
    stop = threading.Event()
    server = _Server(device, link_path, stop)
    server.new_pty()
    thread = threading.Thread(target=server.run, name=f"pty-{name}", daemon=True)
    link = PtyLink(str(link_path), device, stop, thread, server.errors, server)
    thread.start()
    try:
        yield link
    finally:
        stop.set()
        thread.join(2.0)
        for p in (link_path, link_path.with_suffix(".new"), folder / PTY_OWNER_FILE):
            with contextlib.suppress(FileNotFoundError):
                p.unlink()
        with contextlib.suppress(OSError):
            folder.rmdir()


@contextlib.contextmanager
def sigterm_as_ctrl_c() -> Iterator[None]:
    """SIGTERM raises KeyboardInterrupt while an emulator's command-line tool serves, so that
    it ends as Ctrl-C does (the pty's temporary folder removed, not left in /tmp); the handler
    before is put back when serving ends.

    Why put back: the tools' ``main`` is also called in-process (tests), and the handler it had
    left made a later SIGTERM to that process a KeyboardInterrupt wherever it landed."""
    if threading.current_thread() is not threading.main_thread():
        yield  # handlers can only be set from the main thread
        return
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
