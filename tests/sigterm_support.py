"""Shared by the SIGTERM tests of commands run in-process (plan, calibrate-lights): the
signal is sent to this process from inside the command, at the point under test (no sleeps),
and a command that installed no handler fails the test rather than ending the test process."""

from __future__ import annotations

import os
import signal
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any


class Unhandled(Exception):
    """Raised by the test's own SIGTERM handler: the command installed none (without one, the
    signal would end the test process itself)."""


@contextmanager
def sigterm_fails_the_test(command: str) -> Iterator[None]:
    """Within it, a SIGTERM the command under test does not handle raises :class:`Unhandled`
    naming ``command``; the handler before is put back after. The handler is named
    ``unhandled``: a test checks the command put it back by that name."""

    def unhandled(signum: int, frame: Any) -> None:
        raise Unhandled(f"SIGTERM reached the test's handler: {command} installed none")

    previous = signal.signal(signal.SIGTERM, unhandled)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def terminated() -> None:
    """This process is sent SIGTERM, as `timeout` or a service manager sends it; its handler
    runs at the next bytecode, so the statement after this one is not reached."""
    os.kill(os.getpid(), signal.SIGTERM)


#: ``python -c`` source of an ``rti-rig`` run that sends itself ``{signal}`` as image ``AT``
#: (0-based, its first argument, popped) is committed: the commit holds the signal, which
#: stops the run right after that image (no sleeps, no timing)
_SIGNAL_AT_COMMIT = """
import os, signal, sys
from rti_rig.runtime.session import SessionFolder
AT = int(sys.argv.pop(1))
real = SessionFolder.write_step
def write_step(self, i, *a, **k):
    if i == AT:
        os.kill(os.getpid(), signal.{signal})
    return real(self, i, *a, **k)
SessionFolder.write_step = write_step
from rti_rig.cli import app
app(sys.argv[1:], prog_name="rti-rig")
"""


def signal_at_commit(name: str) -> str:
    """:data:`_SIGNAL_AT_COMMIT` for signal ``name`` (``"SIGTERM"``, ``"SIGINT"``)."""
    return _SIGNAL_AT_COMMIT.replace("{signal}", name)
