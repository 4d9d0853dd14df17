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
