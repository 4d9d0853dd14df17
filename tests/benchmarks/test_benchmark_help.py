"""Every benchmark script answers --help with what it does, instead of running (minutes)."""

from __future__ import annotations

import runpy
import signal
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
#: Seconds a script may take to answer --help (an import under a loaded CI machine).
HELP_WITHIN_S = 120
SCRIPTS = sorted(
    p.stem
    for p in (REPO / "benchmarks").glob("*.py")
    if '__name__ == "__main__"' in p.read_text(encoding="utf-8")
)


@pytest.mark.parametrize("script", SCRIPTS)
def test_help_describes_and_does_not_run(
    script: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(sys, "argv", [f"benchmarks/{script}.py", "--help"])

    def ran(signum, frame):  # type: ignore[no-untyped-def]
        pytest.fail(f"benchmarks.{script} --help ran the benchmark instead of answering")

    # answering takes an import (seconds); a script that runs instead is stopped, not waited for
    previous = signal.signal(signal.SIGALRM, ran)
    signal.alarm(HELP_WITHIN_S)
    try:
        with pytest.raises(SystemExit) as done:
            runpy.run_module(f"benchmarks.{script}", run_name="__main__", alter_sys=False)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    assert done.value.code in (0, None)
    text = capsys.readouterr().out
    assert text.strip(), "no help text"
    assert "--write" in text or "usage:" in text
