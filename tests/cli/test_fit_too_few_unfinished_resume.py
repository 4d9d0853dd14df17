"""``fit`` of a session stopped with too few images for any model says how to resume it.

Found by an audit: a session stopped after 2 of its 12 images was told "no candidate model
can be fitted from 2 image(s) … shoot more lights", and not that ``rti-rig run --resume``
shoots the lights it still plans. A finished session with as few images is not told to
resume (there is nothing left to shoot).
"""

from __future__ import annotations

import shlex
from pathlib import Path

from conftest import CONFIGS, cut_new_session, said
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

RIG = CONFIGS / "simulated_dome.toml"


def test_a_stopped_session_too_few_to_fit_is_told_how_to_resume(tmp_path: Path) -> None:
    stopped = tmp_path / "stopped"
    request = NewSessionRequest(RIG, stopped, lights=12)
    assert cut_new_session(request, after_step=1).finish_reason is FinishReason.CANCELLED
    r = CliRunner().invoke(app, ["fit", str(stopped), "--out", str(tmp_path / "f")])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "shoot more lights" in text, text
    resume = "the session is not finished: continue it with rti-rig run --resume "
    assert resume + shlex.quote(str(stopped)) in text, text
    assert "Traceback" not in r.output


def test_a_finished_session_too_few_to_fit_is_not_told_to_resume(tmp_path: Path) -> None:
    done = tmp_path / "done"
    r = CliRunner().invoke(
        app, ["run", str(RIG), "--out", str(done), "--lights", "2", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    r = CliRunner().invoke(app, ["fit", str(done), "--out", str(tmp_path / "f")])
    assert r.exit_code == 2, r.output
    text = said(r)
    assert "shoot more lights" in text, text
    assert "--resume" not in text, text
