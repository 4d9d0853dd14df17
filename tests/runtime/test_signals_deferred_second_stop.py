"""A second stop while a driver holds SIGINT/SIGTERM over a serial port's opening.

The drivers hold the signals over the opening so that a stop cannot leak the descriptor
pyserial has not kept yet; but an opening can hang (a wedged USB adapter), and every Ctrl-C
and SIGTERM had been held until it returned: the only way out was SIGKILL, which skips the
teardown's all-off. With ``second_stops`` the second one ends the hold where the block is.
"""

from __future__ import annotations

import signal
from typing import Any

import pytest

from rti_rig.core.deferred_signals import signal_handlers, signals_deferred


class Stop(BaseException):
    pass


def test_a_second_stop_ends_the_hold_and_both_are_delivered_in_order() -> None:
    seen: list[int] = []
    reached: list[str] = []

    def first_cancels_second_stops(signum: int, frame: Any) -> None:  # run's own rule
        seen.append(signum)
        if len(seen) > 1:
            raise Stop

    wanted = {signal.SIGINT: first_cancels_second_stops, signal.SIGTERM: first_cancels_second_stops}
    with signal_handlers(wanted), pytest.raises(Stop), signals_deferred(second_stops=True):
        signal.raise_signal(signal.SIGINT)
        reached.append("held the first")
        signal.raise_signal(signal.SIGTERM)  # the opening hangs; the user insists
        reached.append("past the second")  # the hold had kept it until the block ended
    assert reached == ["held the first"]
    assert seen == [signal.SIGINT, signal.SIGTERM]


def test_one_stop_is_still_held_until_the_block_is_through() -> None:
    reached: list[str] = []

    def stop(signum: int, frame: Any) -> None:
        raise Stop

    stopped = pytest.raises(Stop)
    with signal_handlers({signal.SIGINT: stop}), stopped, signals_deferred(second_stops=True):
        signal.raise_signal(signal.SIGINT)
        reached.append("the port is kept")
    assert reached == ["the port is kept"]


def test_after_a_second_stop_the_handlers_in_place_are_the_callers() -> None:
    def quiet(signum: int, frame: Any) -> None:
        pass

    with signal_handlers({signal.SIGINT: quiet, signal.SIGTERM: quiet}):
        with signals_deferred(second_stops=True):
            signal.raise_signal(signal.SIGINT)
            signal.raise_signal(signal.SIGINT)
            assert signal.getsignal(signal.SIGINT) is quiet  # unheld from here on
            assert signal.getsignal(signal.SIGTERM) is quiet
        assert signal.getsignal(signal.SIGINT) is quiet


def test_inside_the_teardowns_hold_a_second_stop_stays_held() -> None:
    """The teardown's all-off reopens the port: there its own hold, which nothing ends, wins."""
    reached: list[str] = []

    def stop(signum: int, frame: Any) -> None:
        raise Stop

    with signal_handlers({signal.SIGINT: stop}), pytest.raises(Stop), signals_deferred():
        with signals_deferred(second_stops=True):
            signal.raise_signal(signal.SIGINT)
            signal.raise_signal(signal.SIGINT)
            reached.append("opened")
        reached.append("all-off sent")
    assert reached == ["opened", "all-off sent"]


class Named(BaseException):
    pass


@pytest.mark.parametrize("second_stops", [False, True], ids=["held", "second-stops"])
def test_stops_one_hold_delivers_are_raised_first_and_the_rest_kept_in_its_notes(
    second_stops: bool,
) -> None:
    """Only the first exception can be raised (it keeps the first stop's teardown); the later
    one had been dropped without a trace."""

    def named(signum: int, frame: Any) -> None:
        raise Named(signal.Signals(signum).name)

    wanted = {signal.SIGINT: named, signal.SIGTERM: named}
    held = signals_deferred(second_stops=second_stops)
    with signal_handlers(wanted), pytest.raises(Named) as caught, held:
        signal.raise_signal(signal.SIGTERM)
        signal.raise_signal(signal.SIGINT)
    assert str(caught.value) == "SIGTERM"
    assert getattr(caught.value, "__notes__", []) == [
        "also raised as the hold ended: Named: SIGINT"
    ]


def test_a_stop_raised_as_the_hold_is_set_leaves_no_hold_behind(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A stop whose handler raises between the hold's two swaps (SIGINT already held,
    SIGTERM's own handler still in place) puts SIGINT's handler back: it had stayed the hold
    of a block that never began, every later Ctrl-C kept where nobody would deliver it (the
    controller's teardown sets its hold again after such a stop)."""
    import rti_rig.core.deferred_signals as deferred

    def ours(signum: int, frame: Any) -> None:
        raise Stop

    real_getsignal = signal.getsignal

    def getsignal(sig: int) -> Any:
        if sig == signal.SIGTERM:  # SIGINT is swapped by now: the stop lands between the two
            signal.raise_signal(signal.SIGTERM)
        return real_getsignal(sig)

    with signal_handlers({signal.SIGINT: ours, signal.SIGTERM: ours}):
        monkeypatch.setattr(deferred.signal, "getsignal", getsignal)
        with pytest.raises(Stop), signals_deferred():
            raise AssertionError("the block began though its hold was cut short")
        monkeypatch.undo()
        assert signal.getsignal(signal.SIGINT) is ours
        assert signal.getsignal(signal.SIGTERM) is ours
