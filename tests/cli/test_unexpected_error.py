"""A fault no part of rti-rig named (an OSError or a library's own exception from a device)
ends a run with what is known, never with a Python traceback."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


class _Unnamed(Exception):
    """Stands for an exception a driver let through (pyserial's, tifffile's, OSError)."""


def _camera_failing_at(monkeypatch: pytest.MonkeyPatch, at: int) -> None:
    import rti_rig.app.compose as compose

    real_build = compose.build_rig

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        rig = real_build(*args, **kwargs)
        real_capture, calls = rig.camera.capture, {"n": 0}

        def capture(exposure_s: float):  # type: ignore[no-untyped-def]
            calls["n"] += 1
            if calls["n"] == at + 1:
                raise _Unnamed("the device said something no one expected")
            return real_capture(exposure_s)

        rig.camera.capture = capture
        return rig

    monkeypatch.setattr(compose, "build_rig", build)


def test_an_unnamed_fault_mid_session_says_the_lights_the_images_and_the_resume(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    _camera_failing_at(monkeypatch, 3)
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6", "--no-verdict"])
    said = " ".join(r.output.split())
    assert isinstance(r.exception, SystemExit) and r.exit_code == 1, r.output
    assert "Traceback" not in r.output
    assert "unexpected _Unnamed: the device said something no one expected" in said
    assert "Lights were switched off" in said  # the teardown ran, and is said
    assert f"3 image(s) kept in {out}" in said and f"rti-rig run --resume {out}" in said
    monkeypatch.undo()
    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert "6 image(s) in the session" in " ".join(r.output.split())


def test_an_unnamed_fault_while_the_session_opens_is_said_too(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import rti_rig.app.compose as compose

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise _Unnamed("no rig today")

    monkeypatch.setattr(compose, "build_rig", build)
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "6"])
    said = " ".join(r.output.split())
    assert isinstance(r.exception, SystemExit) and r.exit_code == 1, r.output
    assert "unexpected _Unnamed: no rig today" in said
    assert f"Nothing was captured or written to {out}" in said


def test_an_unnamed_fault_while_the_preview_opens_is_said_too(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`preview` opened its session through its own copy of `run`'s opening, without the
    answer to a fault no part of rti-rig named: it reached the user as a traceback."""
    import rti_rig.app.compose as compose

    def build(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise _Unnamed("no rig today")

    monkeypatch.setattr(compose, "build_rig", build)
    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "p"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(out)])
    said = " ".join(r.output.split())
    assert isinstance(r.exception, SystemExit) and r.exit_code == 1, (r.exception, r.output)
    assert "unexpected _Unnamed: no rig today" in said, said
    assert f"Nothing was captured or written to {out}" in said, said


def test_an_unnamed_fault_while_a_finished_sessions_journal_is_rebuilt_is_said_too(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`run --resume DIR --rebuild-journal` of a completed session opened through a third copy
    of the opening code, without the answer to a fault no part of rti-rig named: it reached
    the user as a traceback."""
    import rti_rig.app.usecases.session as usecase

    cfg = write_config(tmp_path, SMALL_DOME)
    out = tmp_path / "s"
    assert runner.invoke(app, ["run", str(cfg), "--out", str(out), "--lights", "3"]).exit_code == 0

    def rebuild(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise _Unnamed("no journal today")

    monkeypatch.setattr(usecase, "rebuild_finished_session", rebuild)
    r = runner.invoke(app, ["run", "--resume", str(out), "--rebuild-journal"])
    said = " ".join(r.output.split())
    assert isinstance(r.exception, SystemExit) and r.exit_code == 1, (r.exception, r.output)
    assert "unexpected _Unnamed: no journal today" in said, said
    assert f"--resume {out} --rebuild-journal again once it is fixed" in said, said
