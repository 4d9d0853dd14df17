"""A stop whose handler raises as the capture ends, after the loop's last step (or its break)
and before the teardown's hold is set, still gets the teardown: the lights' safe state (the
all-off) and the session's end in the manifest, named as the stop it was.

Python runs a signal handler between any two bytecodes of the main thread; the teardown is a
``finally`` whose first statements ran unheld, so the CLI's SIGTERM handler (which raises
EmergencyStop), a second Ctrl-C's, or Python's own KeyboardInterrupt landing there left the
``finally`` at once: no all-off, no camera or port closed, no end in the manifest. The signal is
raised here at that very point, as the teardown asks for its hold (no timing).
"""

from __future__ import annotations

import json
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import SMALL_DOME, write_config

import rti_rig.runtime.controller as controller
from rti_rig.app.compose import build_rig
from rti_rig.app.config import load_rig_config
from rti_rig.planner.uniform import plan_uniform
from rti_rig.runtime.controller import CancelToken, EmergencyStop, StepCompleted, run_session
from rti_rig.runtime.session import SessionFolder

STEPS = 3


def _raises_emergency_stop(signum: int, frame: Any) -> None:
    """As the CLI's SIGTERM handler (and its second Ctrl-C's) does."""
    raise EmergencyStop(signal.Signals(signum))


@pytest.mark.parametrize(
    ("signum", "handler", "raised", "reason", "ending"),
    [
        (signal.SIGTERM, _raises_emergency_stop, EmergencyStop, "emergency-stop", "completed"),
        (signal.SIGINT, signal.default_int_handler, KeyboardInterrupt, "interrupted", "cancelled"),
    ],
    ids=["sigterm-as-the-cli-after-the-last-step", "ctrl-c-unhandled-after-a-break"],
)
def test_a_stop_landing_before_the_teardown_hold_still_tears_down(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    signum: signal.Signals,
    handler: Any,
    raised: type[BaseException],
    reason: str,
    ending: str,
) -> None:
    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    cancel = CancelToken()
    commits = {"n": 0}
    real_hold = controller.signals_deferred
    landed: list[bool] = []

    def hold(*args: Any, **kwargs: Any) -> Any:
        # the commits' holds come first, one an image; the next is the teardown's
        if commits["n"] == kept and not landed:
            landed.append(True)
            signal.raise_signal(signum)  # its handler runs here, before the hold is set
        commits["n"] += 1
        return real_hold(*args, **kwargs)

    kept = STEPS if ending == "completed" else 1

    def on_event(event: Any) -> None:
        if ending == "cancelled" and isinstance(event, StepCompleted) and event.index == 0:
            cancel.cancel()  # the loop breaks before its next step

    safe_calls: list[bool] = []
    real_safe = rig.lighting.safe

    def safe(*, emergency: bool = False) -> Any:
        safe_calls.append(emergency)
        return real_safe(emergency=emergency)

    monkeypatch.setattr(rig.lighting, "safe", safe)
    monkeypatch.setattr(controller, "signals_deferred", hold)
    previous = signal.signal(signum, handler)
    out = tmp_path / "s"
    try:
        with pytest.raises(raised):
            run_session(
                rig,
                plan_uniform(rig.geometry, STEPS),
                SessionFolder.create(out, STEPS),
                cancel=cancel,
                on_event=on_event,
            )
    finally:
        signal.signal(signum, previous)
    assert landed, "the signal was never raised where the test meant"
    assert safe_calls == [reason == "emergency-stop"]  # the lights' all-off was sent
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == reason
    assert runner["steps_done_this_run"] == kept
    assert cancel.over
    assert rig.lighting.source.lit is None  # type: ignore[attr-defined]


@pytest.fixture(autouse=True)
def _handlers_put_back() -> Iterator[None]:
    """However a test ends, SIGINT and SIGTERM answer as before it."""
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    yield
    for s, h in before.items():
        signal.signal(s, h)


def _run_with_capture_over(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, raising: Any) -> Any:
    """A session of STEPS whose teardown's ``capture_over`` raises what ``raising(n)`` gives
    on its n-th call (None: it returns); the all-off calls seen and the folder."""
    rig = build_rig(load_rig_config(write_config(tmp_path, SMALL_DOME)))
    calls = {"n": 0}
    real_over = CancelToken.capture_over

    def capture_over(self: CancelToken) -> None:
        calls["n"] += 1
        exc = raising(calls["n"])
        if exc is not None:
            raise exc
        real_over(self)

    safe_calls: list[bool] = []
    real_safe = rig.lighting.safe

    def safe(*, emergency: bool = False) -> Any:
        safe_calls.append(emergency)
        return real_safe(emergency=emergency)

    monkeypatch.setattr(rig.lighting, "safe", safe)
    monkeypatch.setattr(CancelToken, "capture_over", capture_over)
    out = tmp_path / "s"
    run = lambda: run_session(  # noqa: E731
        rig, plan_uniform(rig.geometry, STEPS), SessionFolder.create(out, STEPS)
    )
    return run, calls, safe_calls, out, rig


def test_a_fault_recurring_as_the_teardown_hold_is_set_is_tried_a_bounded_number_of_times(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before, every exception there was tried again without limit: one that always recurs
    spun for ever, the lights never switched off. It recurs here 1000 times (then stops, so
    that the unbounded loop ends in a failure rather than a hang)."""
    run, calls, safe_calls, out, rig = _run_with_capture_over(
        tmp_path, monkeypatch, lambda n: RuntimeError("hold fault") if n <= 1000 else None
    )
    with pytest.raises(RuntimeError, match="hold fault"):
        run()
    assert calls["n"] == controller._HOLD_TRIES, calls  # bounded, not the 1001 to get through
    assert safe_calls == [False]  # the teardown ran all the same: the all-off was sent
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == "error" and "hold fault" in runner["error"], runner
    assert rig.lighting.source.lit is None


def test_a_second_stop_as_the_teardown_hold_is_set_is_noted_on_the_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before, a second stop caught there was dropped without a trace: the first is raised
    (it names the run's end), the second in its notes."""
    stops = {1: EmergencyStop(signal.SIGTERM), 2: KeyboardInterrupt("second Ctrl-C")}
    run, _calls, safe_calls, out, _rig = _run_with_capture_over(tmp_path, monkeypatch, stops.get)
    with pytest.raises(EmergencyStop) as raised:
        run()
    notes = getattr(raised.value, "__notes__", [])
    assert any("KeyboardInterrupt" in n and "second Ctrl-C" in n for n in notes), notes
    assert safe_calls == [True]
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == "emergency-stop", runner
