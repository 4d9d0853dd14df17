"""A stop (Ctrl-C) during the scheduler probe leaves no coroutine of its event loop to be
closed after the loop is: such a coroutine, closed later by the garbage collector, closes its
half-made connection on the closed loop and Python prints "Exception ignored in: <coroutine
object open_connection …> Traceback … Event loop is closed" under "Stopped (Ctrl-C)".

CI met it once in thousands of runs (the test of a Ctrl-C on a silent port): the Ctrl-C cut
through the probe's coroutines at a moment that left one suspended, held by the stop's own
traceback or by a task the stop had left pending. These tests make both cases on purpose.
"""

from __future__ import annotations

import asyncio
import gc
import os
import signal
import sys
import warnings
from collections.abc import Iterator
from typing import Any

import pytest

from rti_rig.app.usecases.scheduler_probe import _run_quietly


@pytest.fixture
def unraisable() -> Iterator[list[Any]]:
    """What Python would print as "Exception ignored in: …" while the test runs."""
    seen: list[Any] = []
    before = sys.unraisablehook
    sys.unraisablehook = seen.append
    try:
        yield seen
    finally:
        sys.unraisablehook = before


async def _half_made_connection(opened: asyncio.Event) -> None:
    """Like asyncio's connection set-up: suspended on a future, and closing its transport on
    the loop (``call_soon``) if it is ended there."""
    loop = asyncio.get_running_loop()
    opened.set()
    try:
        await loop.create_future()  # never resolved
    except BaseException:
        loop.call_soon(lambda: None)  # transport.close(): fails on a closed loop
        raise


def _no_coroutine_closed_on_a_closed_loop(seen: list[Any]) -> None:
    gc.collect()
    assert [str(s.exc_value) for s in seen] == []


def test_a_stop_that_leaves_a_coroutine_suspended_in_its_traceback(
    unraisable: list[Any],
) -> None:
    """The Ctrl-C is raised in a frame that awaits another coroutine (not a task): the
    awaited one is left suspended, referenced only by the stop's traceback."""

    async def main() -> None:
        opened = asyncio.Event()
        inner = _half_made_connection(opened)
        inner.send(None)  # started and suspended, as a coroutine awaited by this frame is
        assert opened.is_set()
        raise KeyboardInterrupt  # the Ctrl-C lands here, in this frame, not in ``inner``

    with pytest.raises(KeyboardInterrupt):
        _run_quietly(main)
    _no_coroutine_closed_on_a_closed_loop(unraisable)


def test_a_stop_that_leaves_a_task_that_outlives_its_cancellation(
    unraisable: list[Any],
) -> None:
    """A task still pending after the bounded wait for the cancelled tasks is ended while
    its loop is open, not left to the garbage collector."""

    async def stubborn(opened: asyncio.Event) -> None:
        loop = asyncio.get_running_loop()
        opened.set()
        try:
            while True:
                try:
                    await asyncio.sleep(3600)
                except asyncio.CancelledError:
                    continue  # outlives the bounded wait
        finally:
            loop.call_soon(lambda: None)

    async def main() -> None:
        opened = asyncio.Event()
        task = asyncio.get_running_loop().create_task(stubborn(opened))
        await opened.wait()
        del task
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _run_quietly(main)
    _no_coroutine_closed_on_a_closed_loop(unraisable)


def test_a_probe_that_ends_normally_is_returned() -> None:
    async def main() -> int:
        await asyncio.sleep(0)
        return 7

    assert _run_quietly(main) == 7


class _StoppedAsItStarts(asyncio.SelectorEventLoop):
    """A loop whose ``run_until_complete`` is cut by a Ctrl-C in its first lines, before it
    wraps the coroutine in a task (where a real one can land)."""

    def run_until_complete(self, future: Any) -> Any:
        if asyncio.iscoroutine(future) and not getattr(self, "stopped", False):
            self.stopped = True
            raise KeyboardInterrupt
        return super().run_until_complete(future)


def test_a_stop_before_the_coroutine_is_started_leaves_it_closed_not_unawaited(
    monkeypatch: pytest.MonkeyPatch, unraisable: list[Any]
) -> None:
    """The stopped fit said "note: coroutine 'probe.<locals>.bounded' was never awaited"
    under "Stopped (Ctrl-C)": the coroutine, made before the loop took it, was never
    started."""
    loops: list[_StoppedAsItStarts] = []

    def new_event_loop() -> asyncio.AbstractEventLoop:
        loops.append(_StoppedAsItStarts())
        return loops[-1]

    async def main() -> int:
        return 7

    monkeypatch.setattr(asyncio, "new_event_loop", new_event_loop)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        with pytest.raises(KeyboardInterrupt):
            _run_quietly(main)
        gc.collect()
    assert [str(w.message) for w in said if "never awaited" in str(w.message)] == []
    assert [loop.is_closed() for loop in loops] == [True]
    _no_coroutine_closed_on_a_closed_loop(unraisable)


def test_a_stop_while_the_loop_is_made_leaves_no_coroutine_unawaited(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def new_event_loop() -> asyncio.AbstractEventLoop:
        raise KeyboardInterrupt  # the Ctrl-C lands while the loop is being made

    async def main() -> None:
        pass

    monkeypatch.setattr(asyncio, "new_event_loop", new_event_loop)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        with pytest.raises(KeyboardInterrupt):
            _run_quietly(main)
        gc.collect()
    assert [str(w.message) for w in said if "never awaited" in str(w.message)] == []


@pytest.fixture
def python_ctrl_c() -> Iterator[None]:
    """SIGINT as a shell gives ``rti-rig fit``: Python's own handler (this pytest process
    may have had it ignored by an earlier in-process ``run``)."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_ctrl_c_that_lands_in_a_finalizer_still_stops_the_probe(
    python_ctrl_c: None, unraisable: list[Any]
) -> None:
    """CI, under load: the Ctrl-C came while the garbage collector ran a half-made
    connection's ``StreamWriter.__del__``; Python raised its KeyboardInterrupt there, printed
    it as "Exception ignored in …" and dropped it, and the stopped fit waited out the silent
    port's 20 s. Here the Ctrl-C is sent from inside a finalizer on purpose: without the
    loop's own handler this probe runs its 30 s out and returns."""

    class Dropped:
        def __del__(self) -> None:
            os.kill(os.getpid(), signal.SIGINT)
            sum(range(10_000))  # Python's handler would raise here, inside __del__

    async def main() -> str:
        Dropped()  # dropped at once: its __del__ runs now, in this frame
        await asyncio.sleep(30)
        return "waited it out"

    with pytest.raises(KeyboardInterrupt):
        _run_quietly(main)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # given back
    _no_coroutine_closed_on_a_closed_loop(unraisable)


def test_a_ctrl_c_that_is_ignored_stays_ignored_during_the_probe() -> None:
    """A caller that ignores SIGINT (``run`` once its session is over) keeps it ignored."""
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:

        async def main() -> int:
            os.kill(os.getpid(), signal.SIGINT)
            await asyncio.sleep(0.05)
            return 7

        assert _run_quietly(main) == 7
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)
