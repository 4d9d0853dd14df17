"""A hang-up answered as a SIGTERM is named SIGHUP for its own delivery only: a real SIGTERM
after it (a supervisor's ``kill`` once the terminal had closed) is named SIGTERM, and one
before it stays SIGTERM.

Before, ``hangup_as_sigterm`` set a flag at the hang-up that stayed set to the block's end,
and every SIGTERM named after it (its words, the manifest's record, the exit code) was called
SIGHUP. The signals are raised in this process, so their handlers run in order, in the main
thread (no timing).
"""

from __future__ import annotations

import signal
import sys

import pytest

from rti_rig.cli.app import stop_exit_code
from rti_rig.cli.stopping import Terminated, sigterm_stops, stop_signal
from rti_rig.core.deferred_signals import (
    as_received,
    hangup_as_sigterm,
    signal_handlers,
    signals_deferred,
)

pytestmark = pytest.mark.skipif(
    sys.platform != "linux" or not hasattr(signal, "SIGHUP"), reason="signals tested on Linux"
)


def test_a_sigterm_after_a_hangup_is_named_sigterm() -> None:
    seen: list[signal.Signals] = []
    with (
        signal_handlers({signal.SIGTERM: lambda signum, frame: seen.append(as_received(signum))}),
        hangup_as_sigterm(),
    ):
        signal.raise_signal(signal.SIGTERM)
        signal.raise_signal(signal.SIGHUP)
        signal.raise_signal(signal.SIGTERM)
    assert seen == [signal.SIGTERM, signal.SIGHUP, signal.SIGTERM]


def test_held_stops_are_delivered_and_reported_as_they_came() -> None:
    seen: list[signal.Signals] = []
    held: list[int] = []
    with (
        signal_handlers({signal.SIGTERM: lambda signum, frame: seen.append(as_received(signum))}),
        hangup_as_sigterm(),
    ):
        with signals_deferred(on_held=held.append):
            signal.raise_signal(signal.SIGHUP)
            signal.raise_signal(signal.SIGTERM)
            assert seen == []  # held until the block is done
        signal.raise_signal(signal.SIGTERM)
    assert held == [signal.SIGHUP, signal.SIGTERM]
    assert seen == [signal.SIGHUP, signal.SIGTERM, signal.SIGTERM]


def test_a_command_stopped_by_sigterm_after_a_hangup_exits_143() -> None:
    caught: list[BaseException] = []
    with sigterm_stops():
        for sig in (signal.SIGHUP, signal.SIGTERM):
            try:
                signal.raise_signal(sig)
            except Terminated as exc:
                caught.append(exc)
    assert [stop_signal(e) for e in caught] == [signal.SIGHUP, signal.SIGTERM]
    assert [stop_exit_code(stop_signal(e)) for e in caught] == [129, 143]


def test_the_run_verdicts_stop_keeps_the_signal_as_received() -> None:
    """The run's QA verdict is cut short by a SIGTERM or a hang-up: each is named and exited
    as itself (it had been named by the flag later, as ``fit`` said the verdict's stop)."""
    from rti_rig.cli.session import _verdict_terminable

    caught: list[Terminated] = []
    with hangup_as_sigterm(), _verdict_terminable():
        for sig in (signal.SIGHUP, signal.SIGTERM):
            try:
                signal.raise_signal(sig)
            except Terminated as exc:
                caught.append(exc)
    assert [e.signum for e in caught] == [signal.SIGHUP, signal.SIGTERM]
