"""``rti-rig run`` called in-process leaves SIGINT's handler as it found it.

Its summary is protected from a late Ctrl-C by ignoring SIGINT; that ignore had been set and
left to the caller to undo. Called from Python (CliRunner here, or a lab's script calling the
app), the caller must get its own Ctrl-C back however the command ends, and a Ctrl-C during
the summary must still not cut it. (The conftest's autouse fixture catches any test leaving a
handler changed; this says it of ``run`` directly, with a handler of the caller's own.)
"""

from __future__ import annotations

import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app


@pytest.fixture
def callers_handler() -> Iterator[list[int]]:
    """A SIGINT handler of the caller's own (not Python's default): what ``run`` must put back.
    Yields the signals it received."""
    got: list[int] = []

    def caller(signum: int, frame: Any) -> None:
        got.append(signum)

    before = signal.signal(signal.SIGINT, caller)
    try:
        yield got
        assert signal.getsignal(signal.SIGINT) is caller, "run did not put the handler back"
    finally:
        signal.signal(signal.SIGINT, before)


def _ctrl_c_in_the_summary(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """A Ctrl-C raised as the summary's time line is made (a known point of the summary)."""
    import rti_rig.cli.session as cs

    real = cs._time_line
    calls: list[str] = []

    def hooked(*args: Any, **kwargs: Any) -> str:
        calls.append("summary")
        signal.raise_signal(signal.SIGINT)
        return real(*args, **kwargs)

    monkeypatch.setattr(cs, "_time_line", hooked)
    return calls


def test_a_completed_run_puts_the_callers_ctrl_c_back(
    tmp_path: Path, callers_handler: list[int], monkeypatch: pytest.MonkeyPatch
) -> None:
    summary = _ctrl_c_in_the_summary(monkeypatch)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "4"],
    )
    assert r.exit_code == 0, said(r)
    assert summary, "the summary was not made"
    assert "4 image(s) in the session" in r.output  # the summary went on, whole
    assert "Session time" in r.output
    assert callers_handler == []  # the Ctrl-C in the summary was ignored, not passed on
    assert signal.getsignal(signal.SIGINT) is not signal.SIG_IGN


def test_a_run_stopped_by_ctrl_c_puts_the_callers_ctrl_c_back(
    tmp_path: Path, callers_handler: list[int], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Stopped by a Ctrl-C after its first image: the command ends with ``typer.Exit``."""
    import rti_rig.app.usecases.session as usecase
    from rti_rig.runtime.controller import StepCompleted

    real = usecase.run_opened_session

    def ctrl_c_after_the_first_image(opened, cancel=None, on_event=None):  # type: ignore[no-untyped-def]
        def on(event):  # type: ignore[no-untyped-def]
            if on_event is not None:
                on_event(event)
            if isinstance(event, StepCompleted) and event.index == 0:
                signal.raise_signal(signal.SIGINT)  # the run's own handler: stop after it

        return real(opened, cancel, on)

    monkeypatch.setattr(usecase, "run_opened_session", ctrl_c_after_the_first_image)
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "4"],
    )
    assert r.exit_code == 130, said(r)
    assert "cancelled" in said(r)
    assert callers_handler == []  # the run's handler answered it, not the caller's
