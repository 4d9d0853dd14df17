"""A single ``rti-rig fit S --out F`` whose session changes while it is fitted says so and
exits 1, as a batch does for each of its sessions.

A single fit had exited 0 with "Wrote … files", its fit of 5 images beside a session a
resume had brought to 8 while the fit ran (a batch says "but its session changed while it
was being fitted" and exits 1). The resume is made once the fit has read and written
everything, as a capture running beside the fit would make it.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import SMALL_DOME, interrupted, said, write_config
from typer.testing import CliRunner

from rti_rig.app.usecases import fit as fit_usecase
from rti_rig.cli import app

runner = CliRunner()


def fit(source: Path, out: Path):  # type: ignore[no-untyped-def]
    """``rti-rig fit S --out OUT`` as a user runs it (PS: any light count from 3 fits)."""
    args = ["fit", str(source), "--out", str(out), "--model", "ps", "--no-qa"]
    return runner.invoke(app, args, terminal_width=400)


@pytest.mark.e2e
@pytest.mark.slow
def test_a_session_resumed_while_a_single_fit_runs_is_said_and_exits_1(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s, f = tmp_path / "S", tmp_path / "F"
    interrupted(cfg, s, after_step=4, lights=8)
    real = fit_usecase.run_fit

    def fit_then_resume(req, bands=None):  # type: ignore[no-untyped-def]
        result = real(req, bands)
        r = runner.invoke(app, ["run", "--resume", str(s)])
        assert r.exit_code == 0, r.output
        return result

    monkeypatch.setattr(fit_usecase, "run_fit", fit_then_resume)
    r = fit(s, f)
    text = said(r)
    assert r.exit_code == 1, r.output
    assert "Traceback" not in text, r.output
    assert f"{s} changed while it was being fitted (5 → 8 images)" in text, r.output
    assert f"the fit in {f} is of the session as it was read" in text, r.output
    assert "fit it again into a new --out" in text, r.output
    record = json.loads((f / "fit.json").read_text(encoding="utf-8"))
    assert str(record["read"]).startswith("5 images"), record["read"]
    monkeypatch.undo()
    r = fit(s, tmp_path / "F2")  # as said: a fit of the session there now, exit 0
    assert r.exit_code == 0, r.output
    assert "changed while it was being fitted" not in said(r), r.output


@pytest.mark.e2e
@pytest.mark.slow
def test_a_single_fit_of_a_session_left_alone_exits_0(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s = tmp_path / "S"
    interrupted(cfg, s, after_step=4, lights=8)
    r = fit(s, tmp_path / "F")
    assert r.exit_code == 0, r.output
    assert "changed while it was being fitted" not in said(r), r.output
