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
    # a help that offers --write is kept: the script writes into docs/ (flash_sync_slips,
    # flash_sync_statistics and real_led_effects had offered it, written nothing, and run on
    # for minutes, the user believing the recorded table refreshed)
    source = (REPO / "benchmarks" / f"{script}.py").read_text(encoding="utf-8")
    if "update the figures in docs/" in text:
        assert any(w in source for w in WRITERS), f"benchmarks.{script} offers --write, writes none"


#: The names through which a benchmark writes its figures into docs/.
WRITERS = ("write_section", "write_asked")


@pytest.mark.parametrize("script", ["flash_sync_slips", "flash_sync_statistics"])
def test_a_script_that_only_prints_refuses_write_before_running(
    script: str, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """--write on a script that writes nothing is refused at once (exit 2), not after its run."""
    monkeypatch.setattr(sys, "argv", [f"benchmarks/{script}.py", "--quick", "--write"])
    with pytest.raises(SystemExit) as done:
        runpy.run_module(f"benchmarks.{script}", run_name="__main__", alter_sys=False)
    assert done.value.code == 2
    said = capsys.readouterr().err
    assert "only prints its figures: it has no --write" in said, said
