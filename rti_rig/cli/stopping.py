"""A SIGTERM that stops a file-writing command as Ctrl-C does, and what a stop left written.

Why: ``plan`` and ``calibrate-lights`` had no SIGTERM handler (``run`` and ``check`` have
theirs; ``fit`` had this one written out as its own and uses it now): a SIGTERM (``timeout``,
a scheduler, a service manager) mid-write ended the process at once, leaving a hidden
``.map.partial.png`` or ``.light_calibration.toml.tmp`` beside the file asked for, and said
nothing. Raised as a BaseException, as KeyboardInterrupt is, the stop runs the writers' own
clean-up (each removes its temporary file on the way out) and is said by the command as its
Ctrl-C is.
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from rti_rig.core.deferred_signals import as_received, hangup_as_sigterm, signal_handlers

#: A file's identity and content stamp (inode, mtime in ns, size), or None where there is none.
Stamp = tuple[int, int, int] | None


class Terminated(BaseException):
    """A SIGTERM during a command that uses :func:`sigterm_stops` (raised by its handler): a
    BaseException so that no ``except Exception`` on the way swallows it and every ``finally``
    (a temporary file removed) runs. ``signum``: the signal as received (SIGHUP for a hang-up
    answered as a SIGTERM), kept as the handler ran: named after it, a hang-up had been
    named SIGTERM, or a SIGTERM SIGHUP."""

    def __init__(self, signum: signal.Signals = signal.SIGTERM) -> None:
        super().__init__(signum)
        self.signum = signum


@contextmanager
def sigterm_stops() -> Iterator[None]:
    """For the block, a SIGTERM raises :class:`Terminated` (the handler before it is put back
    however the block ends), and so does a hang-up (SIGHUP), named and exited as itself (129:
    :func:`~rti_rig.core.deferred_signals.hangup_as_sigterm`; left ignored under ``nohup``).

    Why the hang-up: ``fit``, ``plan`` and ``calibrate-lights`` had no SIGHUP handler, so the
    terminal or ssh connection closing ended them at once, mid-write (a hidden temporary file
    left beside the one asked for) and, for ``calibrate-lights``, with the dome's LED lit."""

    def terminated(signum, frame) -> None:  # type: ignore[no-untyped-def]
        raise Terminated(as_received(signum))

    with signal_handlers({signal.SIGTERM: terminated}), hangup_as_sigterm():
        yield


def stamp(path: Path) -> Stamp:
    """``path``'s stamp now: compared with one taken before the command wrote, it tells whether
    the command wrote the file (its writers replace it by a rename, so a new inode), without
    taking a file left there by an earlier run (``--force``) for one written now."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_ino, st.st_mtime_ns, st.st_size)


def written_since(path: Path, before: Stamp) -> bool:
    """Whether ``path`` is there and is not the file (or the absence) :func:`stamp` saw."""
    now = stamp(path)
    return now is not None and now != before


def stop_signal(exc: BaseException) -> signal.Signals:
    """The signal a caught stop came from: an
    :class:`~rti_rig.runtime.controller.EmergencyStop`'s own, SIGTERM for :class:`Terminated`,
    else SIGINT (KeyboardInterrupt). The exit code is decided on it (the words said derive
    from it too): it had been decided by comparing the words with "SIGTERM".

    Why the controller is looked up, not imported: a stop is often caught while a command
    still imports lazily (``fit`` imports OpenCV and numpy once its stop handling is set), and
    a Ctrl-C that cut numpy's C core mid-import leaves it unloadable: importing the controller
    here (which imports numpy) then raised "ImportError: cannot load module more than once per
    process", and a traceback reached the user, exit 1, instead of "Stopped (Ctrl-C)". An
    EmergencyStop can only have been raised once its module is loaded."""
    controller = sys.modules.get("rti_rig.runtime.controller")
    if controller is not None and isinstance(exc, controller.EmergencyStop):
        return exc.signum
    return exc.signum if isinstance(exc, Terminated) else signal.SIGINT
