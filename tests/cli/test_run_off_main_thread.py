"""``run`` and ``preview`` called from a thread other than the main one (an application that
calls the CLI's app from a worker thread, as a GUI would).

Python sets signal handlers only in the main thread: ``signal.signal`` raises ValueError
elsewhere. Some of the CLI's handler blocks (SIGUSR1's outside the capture, the capture's own,
the QA verdict's SIGTERM) set theirs unconditionally, and ``run`` from a worker thread ended in
"unexpected ValueError: signal only works in main thread" before its first image. Off the main
thread no handler is set: the caller's, whatever they are, still apply.
"""

from __future__ import annotations

import json
import threading
from pathlib import Path
from typing import Any

from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.cli import app


def _invoke_in_a_thread(args: list[str]) -> Any:
    """The CLI run with ``args`` in a worker thread; its CliRunner result (or what it raised)."""
    outcome: dict[str, Any] = {}

    def work() -> None:
        try:
            outcome["result"] = CliRunner().invoke(app, args, env={"COLUMNS": "300"})
        except BaseException as exc:  # said by the test, not lost in the thread
            outcome["result"] = exc

    worker = threading.Thread(target=work, name="cli-worker")
    worker.start()
    worker.join(timeout=600)  # a slow, shared machine: generous; the join returns at the end
    assert not worker.is_alive(), "the command did not end within 10 minutes"
    result = outcome["result"]
    assert not isinstance(result, BaseException), repr(result)
    return result


def test_run_with_its_verdict_works_from_a_worker_thread(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    r = _invoke_in_a_thread(["run", str(cfg), "--out", str(out), "--lights", "8"])
    assert r.exit_code == 0, r.output
    assert "ValueError" not in r.output
    assert "8 image(s) in the session" in " ".join(r.output.split())
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed"


def test_preview_works_from_a_worker_thread(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "p"
    r = _invoke_in_a_thread(["preview", str(cfg), "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert f"Plan from it: rti-rig plan {out}" in " ".join(r.output.split())
