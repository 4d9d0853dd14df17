"""A QA verdict that fails in a way nothing named ends a complete run in one line, not a
traceback: the session is complete, its lights were switched off, and the verdict is advice.

A MemoryError (the verdict loads the session's images: a large one can exhaust memory) or an
OSError (the disk went away) raised by the verdict escaped ``run`` after its summary ("6
image(s) in the session … lights are off") as a traceback and exit 1, read as a failed capture.
The verdict's own entry is made to fail; everything before it is the emulated dome's real run."""

from __future__ import annotations

import errno
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

import rti_rig.app.usecases.fit as fit_usecase
from rti_rig.cli import app


@pytest.mark.parametrize(
    "error",
    [MemoryError(), OSError(errno.EIO, "Input/output error", "image_004.jpg")],
    ids=["memory", "oserror"],
)
def test_an_unexpected_verdict_failure_is_said_in_one_line_after_a_complete_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, error: Exception
) -> None:
    asked: list[Path] = []

    def failing(session: Path) -> str:
        asked.append(session)
        raise error

    monkeypatch.setattr(fit_usecase, "verdict_for_session", failing)
    out = tmp_path / "s"
    argv = ["run", str(CONFIGS / "emulated_dome.toml"), "--lights", "6", "--out", str(out)]
    r = CliRunner().invoke(app, argv, terminal_width=400)
    text = said(r)
    assert asked, text  # the verdict was reached
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert r.exit_code == 0, text  # the session is complete: the verdict is advice
    assert "6 image(s) in the session" in text, text
    assert "All-off sent and acknowledged by the dome: lights are off." in text, text
    name = type(error).__name__
    assert f"QA verdict unavailable: unexpected {name}" in text, text
    assert f"the session is complete: rti-rig fit {out} --out {out}-fit gives the verdict" in text
    assert "Traceback" not in text, text
    assert len(list(out.glob("image_*.jpg"))) == 6
