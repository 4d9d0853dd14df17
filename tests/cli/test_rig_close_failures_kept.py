"""Every failure of a rig's own close (its emulators, their pseudo-terminals) is kept and said,
and none replaces the error the session stopped on.

Before, the rig's resources were a ``contextlib.ExitStack``: its close raised the last failure
alone, and raised from the session's close on the way out of the capture it replaced the
session's error. A run stopped on a servo's overload ended on "error: unexpected OSError …"
(exit 1), the overload and what to do about it unsaid. Run in-process on the shipped
emulated arm (real Protocol 2.0 packets), as ``run_faulted_arm`` faults it, with two of the
rig's resources failing to close as an emulator whose pty went away may.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, inprocess_arm_config, said, servo_fault
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.runtime.rig import RigResources


def _closes_failing(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Each rig built from here on holds two more resources, each failing to close after the
    emulator's (closed first: the last opened); returns what was closed, in order."""
    import rti_rig.app.compose as compose

    closed: list[str] = []
    real = compose.build_rig

    def build(*args: Any, **kwargs: Any) -> Any:
        rig = real(*args, **kwargs)

        def failing(what: str, errno: int) -> Any:
            def close() -> None:
                closed.append(what)
                raise OSError(errno, f"{what} went away")

            return close

        rig.resources.callback(failing("pty one", 5), "first pty")
        rig.resources.callback(failing("pty two", 9), "second pty")
        return rig

    monkeypatch.setattr(compose, "build_rig", build)
    return closed


def test_an_emulator_close_failure_does_not_hide_the_servo_fault(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    closed = _closes_failing(monkeypatch)
    cfg = inprocess_arm_config(tmp_path, servo_fault(150, 1, "overload"))
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--lights", "12", "--out", str(out), "--no-verdict"]
    )
    text = said(r)
    assert "Traceback" not in text and "unexpected" not in text, text
    assert r.exit_code == 2, text  # the session's error, not an emulator's
    assert "error: arm during 'move to" in text and "hardware fault overload" in text, text
    # the teardown still tried the lamp-off and the stop on the faulted arm
    assert "teardown problem: stop: arm during 'stop'" in text, text
    # both resources were closed, each failure said, in the order they were closed
    assert closed == ["pty two", "pty one"], closed
    two = text.index("teardown problem: second pty close: [Errno 9] pty two went away")
    one = text.index("teardown problem: first pty close: [Errno 5] pty one went away")
    assert two < one, text


@pytest.mark.pty
@pytest.mark.skipif(sys.platform != "linux", reason="pty semantics tested on Linux")
def test_an_emulator_close_failure_does_not_hide_a_failed_all_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The dome is gone at the teardown's all-off (its 8th command, as in
    test_unsafe_end_exit.py): that failure, the lights' line and the unsafe end's exit 1 stand,
    and the emulators' close failures are said after them."""
    closed = _closes_failing(monkeypatch)
    cfg = tmp_path / "rig.toml"
    cfg.write_text(
        (CONFIGS / "emulated_nab_rti_v1.toml")
        .read_text()
        .replace("reconnect_attempts = 4", "reconnect_attempts = 1")
        .replace("reconnect_backoff_s = 0.5", "reconnect_backoff_s = 0.05")
        + '\n[emulator]\nfaults = [{at_command = 8, kind = "disconnect", delay_s = 60.0}]\n'
    )
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        ["run", str(cfg), "--out", str(out), "--lights", "2", "--no-verdict"],
        terminal_width=400,
    )
    text = said(r)
    assert "Traceback" not in text and "unexpected" not in text, text
    assert r.exit_code == 1, text
    assert "teardown problem: all LEDs off" in text, text
    assert "the rig was not brought to a known safe state" in text, text
    assert closed == ["pty two", "pty one"], closed
    assert "teardown problem: second pty close: [Errno 9] pty two went away" in text, text
    assert "teardown problem: first pty close: [Errno 5] pty one went away" in text, text


def test_every_resource_is_closed_and_every_failure_kept() -> None:
    """The rig's resources close last opened first, each whatever the one before did; a second
    close does nothing."""
    done: list[str] = []

    def fails(what: str) -> Any:
        def close() -> None:
            done.append(what)
            raise RuntimeError(f"{what} failed")

        return close

    res = RigResources()
    res.callback(lambda: done.append("a"), "a")
    res.callback(fails("b"), "b")
    res.callback(fails("c"), "c")
    assert res.close() == ["c close: c failed", "b close: b failed"]
    assert done == ["c", "b", "a"]
    assert res.close() == [] and done == ["c", "b", "a"]
