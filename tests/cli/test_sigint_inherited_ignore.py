"""A run started with SIGINT ignored (a script's ``rti-rig run … &``: a shell without job
control starts it so) answers a SIGINT in its QA verdict as it does in its capture.

Before: the capture stopped on one (exit 130, the session resumable), but the verdict that
follows put the inherited ignore back and let every SIGINT pass: a ``kill -INT`` that would
have stopped the capture was not answered for the seconds of QA, and the run ended 0 with the
verdict said. It now ends the verdict as a Ctrl-C does: exit 130, the session complete, the
command that gives its verdict said.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from conftest import CONFIGS

#: the longest a step of this test waits (a loaded CI machine), never the time it takes
BOUND_S = 300.0


def _sigint_ignored() -> None:
    """The child as a shell starts a background command: SIGINT ignored, unblocked."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def test_sigint_in_the_verdict_of_a_run_started_with_it_ignored_ends_the_verdict(
    tmp_path: Path,
) -> None:
    out = tmp_path / "s"
    argv = [sys.executable, "-m", "rti_rig", "run", str(CONFIGS / "simulated_dome.toml")]
    proc = subprocess.Popen(
        [*argv, "--out", str(out), "--lights", "24"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        preexec_fn=_sigint_ignored,
    )
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout or []))
    reader.start()
    try:
        deadline = time.monotonic() + BOUND_S
        # the capture is over once its summary says the session's time: from then on, a
        # SIGINT every 0.02 s (the summary ignores one on purpose; the verdict takes seconds)
        while not any("Session time" in line for line in lines) and proc.poll() is None:
            assert time.monotonic() < deadline, "".join(lines)
            time.sleep(0.05)
        while proc.poll() is None:
            assert time.monotonic() < deadline, "".join(lines)
            proc.send_signal(signal.SIGINT)
            time.sleep(0.02)
    finally:
        if proc.poll() is None:
            proc.kill()
        reader.join(timeout=BOUND_S)
    said = " ".join("".join(lines).split())
    assert proc.returncode == 130, said
    assert "QA verdict skipped (Ctrl-C): the session is complete;" in said, said
    assert f"rti-rig fit {out} --out {out}-fit gives the verdict" in said, said
    assert "Traceback" not in said
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    assert runner["finish_reason"] == "completed", runner


def test_a_stop_before_the_verdicts_own_try_is_said_as_the_verdicts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A SIGINT as the verdict's handlers went in, before the verdict's own ``try`` (CI met it
    once in the test above): the run had said only "rti-rig: stopped (Ctrl-C)", not that the
    session is complete and which command gives its verdict."""
    from typer.testing import CliRunner

    from rti_rig.cli import app
    from rti_rig.cli import fit as cli_fit

    def stopped_at_once(session: Path | None) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli_fit, "print_verdict", stopped_at_once)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "12"]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    said = " ".join(r.output.split())
    assert r.exit_code == 130, said
    assert "QA verdict skipped (Ctrl-C): the session is complete;" in said, said
    assert f"rti-rig fit {out} --out {out}-fit gives the verdict" in said, said
