"""A Ctrl-C landing as ``run`` puts its session's signal handlers back, between the end of the
capture and its summary, neither escapes as a traceback nor cuts the summary.

The summary is printed with Ctrl-C ignored (a late Ctrl-C meant as "stop at once" must not cut
it), but the ignore was set only after the session's handlers had been put back: in between,
Python's own handler was in place, and a Ctrl-C there raised KeyboardInterrupt out of ``run``
(exit 1, no word of the images, the lights or how to go on). The signal is raised at exactly
that point, by the put-back itself (no sleep)."""

from __future__ import annotations

import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

import rti_rig.app.usecases.session as session_usecase
import rti_rig.cli.session as cli_session
from rti_rig.cli import app


@pytest.mark.skipif(sys.platform != "linux", reason="signals tested on Linux")
def test_a_ctrl_c_as_the_session_s_handlers_are_put_back_does_not_cut_the_summary(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    ended: list[str] = []
    real_run, real_put_back = session_usecase.run_opened_session, cli_session.put_back

    def run_opened_session(*args: Any, **kwargs: Any) -> Any:
        result = real_run(*args, **kwargs)
        ended.append("capture")
        return result

    def put_back(previous: Any) -> None:
        real_put_back(previous)
        if ended and "summary" not in ended and signal.SIGINT in previous:
            # a put-back of Ctrl-C's handler after the capture, before the summary: the window
            ended.append("ctrl-c")
            signal.raise_signal(signal.SIGINT)

    def summarise(*args: Any, **kwargs: Any) -> Any:
        ended.append("summary")
        return real_summarise(*args, **kwargs)

    real_summarise = cli_session._summarise
    monkeypatch.setattr(cli_session, "_summarise", summarise)
    monkeypatch.setattr(session_usecase, "run_opened_session", run_opened_session)
    monkeypatch.setattr(cli_session, "put_back", put_back)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "virtual_arm.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, [*argv, "--no-verdict"], terminal_width=400)
    said = " ".join(r.output.split())
    assert ended[:2] == ["capture", "ctrl-c"] and "summary" in ended, said
    assert not isinstance(r.exception, KeyboardInterrupt), said
    assert "6 image(s) in the session" in said, said
    assert "the arm parked (read back" in said, said
    assert r.exit_code == 0, said
    # Ctrl-C is back to what it was once the command is done
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
