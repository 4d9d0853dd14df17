"""``signal_handlers`` and ``put_back``: the one way the CLI sets handlers for a block.

The save, install, restore and main-thread check had been written out by hand in seven places;
two lacked the check (``signal.signal`` raises ValueError off the main thread) and some put a
None (a handler set outside Python) back, which raises TypeError.
"""

from __future__ import annotations

import signal
import threading
from typing import Any

import pytest

from rti_rig.core.deferred_signals import put_back, signal_handlers


def _mark(signum: int, frame: Any) -> None:
    """A handler told apart from any other (never called)."""


def test_the_handlers_are_set_for_the_block_and_put_back_after() -> None:
    before = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    with signal_handlers({signal.SIGTERM: _mark, signal.SIGINT: signal.SIG_IGN}):
        assert signal.getsignal(signal.SIGTERM) is _mark
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    assert (signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)) == before


def test_the_handlers_are_put_back_when_the_block_raises() -> None:
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(RuntimeError, match="block"), signal_handlers({signal.SIGTERM: _mark}):
        raise RuntimeError("in the block")
    assert signal.getsignal(signal.SIGTERM) == before


def test_a_handler_raising_in_the_block_is_acted_on_and_the_previous_put_back() -> None:
    def stop(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt

    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(KeyboardInterrupt), signal_handlers({signal.SIGTERM: stop}):
        signal.raise_signal(signal.SIGTERM)
    assert signal.getsignal(signal.SIGTERM) == before


def test_off_the_main_thread_nothing_is_set_and_nothing_raises() -> None:
    before = signal.getsignal(signal.SIGTERM)
    seen: dict[str, Any] = {}

    def work() -> None:
        try:
            with signal_handlers({signal.SIGTERM: _mark}):
                seen["inside"] = signal.getsignal(signal.SIGTERM)
        except BaseException as exc:  # said by the test, not lost in the thread
            seen["raised"] = exc

    worker = threading.Thread(target=work)
    worker.start()
    worker.join(timeout=60)
    assert not worker.is_alive()
    assert "raised" not in seen, repr(seen.get("raised"))
    assert seen["inside"] == before  # the caller's handler still applies
    assert signal.getsignal(signal.SIGTERM) == before


def test_a_handler_set_outside_python_is_left_rather_than_a_type_error() -> None:
    """``getsignal`` says None for one set from C: it cannot be put back."""
    before = signal.getsignal(signal.SIGTERM)
    put_back({signal.SIGTERM: None})
    assert signal.getsignal(signal.SIGTERM) == before


def test_put_back_off_the_main_thread_returns_rather_than_retrying_for_ever() -> None:
    """``signal.signal`` raises ValueError off the main thread; the swap's retry (meant for a
    pending signal's raising handler) had spun on it for ever."""
    seen: dict[str, Any] = {}

    def work() -> None:
        try:
            put_back({signal.SIGTERM: signal.SIG_DFL})
            seen["returned"] = True
        except BaseException as exc:
            seen["raised"] = exc

    worker = threading.Thread(target=work, daemon=True)
    worker.start()
    worker.join(timeout=60)
    assert not worker.is_alive(), "put_back off the main thread did not return"
    assert seen == {"returned": True}


def test_a_value_signal_signal_refuses_is_raised_not_retried() -> None:
    with pytest.raises(TypeError, match="not a signal handler"):
        put_back({signal.SIGTERM: "not a handler"})


def test_a_signal_whose_handler_was_set_outside_python_is_left_to_it(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A host's C handler (``getsignal`` None) stays in charge: ours could not be put back and
    stayed installed after the block."""
    import rti_rig.core.deferred_signals as deferred

    real_getsignal, real_signal = signal.getsignal, signal.signal
    installed: list[int] = []

    def getsignal(sig: int) -> Any:
        return None if sig == signal.SIGTERM else real_getsignal(sig)

    def set_handler(sig: int, handler: Any) -> Any:
        installed.append(sig)
        return real_signal(sig, handler)

    monkeypatch.setattr(deferred.signal, "getsignal", getsignal)
    monkeypatch.setattr(deferred.signal, "signal", set_handler)
    with signal_handlers({signal.SIGTERM: _mark, signal.SIGINT: signal.SIG_IGN}):
        pass
    monkeypatch.undo()
    assert signal.SIGTERM not in installed
    assert installed.count(signal.SIGINT) == 2  # set, then put back
