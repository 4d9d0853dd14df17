"""A resume of a replay whose images were replaced is refused on the images' digests, not on
how the difference is worded.

Why: ``check_resume_rig`` had told "the recorded images changed, nothing else" by comparing
:func:`~rti_rig.app.rig_identity.identity_differences`' printed lines with
``["recorded images: changed"]``: a rewording of that label silently sent the resume to
another refusal, which no longer said to put the original files back."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp
from tests.conftest import cut_new_session, said

ACQ = Path(__file__).resolve().parents[1] / "data" / "neuralrti_replay"


def test_replaced_images_are_told_whatever_the_label_says(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rti_rig.app import rig_identity
    from rti_rig.app.usecases.session import NewSessionRequest
    from rti_rig.runtime.controller import FinishReason

    acq = tmp_path / "acq"
    shutil.copytree(ACQ, acq)
    out = tmp_path / "s"
    run = cut_new_session(NewSessionRequest(acq / "dirs.lp", out, lights=8), after_step=2)
    assert run.finish_reason is FinishReason.CANCELLED
    lights = read_lp(acq / "dirs.lp")
    shutil.copy(acq / lights[0].name, acq / lights[-1].name)  # an image replaced
    monkeypatch.setitem(rig_identity.LABELS, "recorded_images", "replayed files")
    r = CliRunner().invoke(app, ["run", "--resume", str(out)])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "are not the ones this session began with" in text and "Put the original" in text
    assert "replayed files: changed" not in text, text
