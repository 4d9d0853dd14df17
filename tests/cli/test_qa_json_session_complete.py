"""``qa.json`` says whether the session it judged had completed (``session_complete``).

A session stopped at 8 of its 12 images was ``"good": true`` in ``qa.json``; that it was not
finished was said only in a caveat's words, so a script that read ``good`` after ``fit`` took
a stopped session for one to archive. ``null`` where there is no session record (an ``.lp``
acquisition without a manifest).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from conftest import cut_new_session, shipped_variant
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

SMALL = (("width = 512", "width = 96"), ("height = 512", "height = 96"))


def _qa_json(session: Path, out: Path) -> dict:  # type: ignore[type-arg]
    r = CliRunner().invoke(
        app, ["fit", str(session), "--out", str(out), "--no-ptm", "--no-hsh", "--no-normals"]
    )
    assert r.exit_code == 0, r.output
    return json.loads((out / "qa.json").read_text())


def test_qa_json_says_whether_the_session_completed(tmp_path: Path) -> None:
    # the shipped dome at 96 px: whether a session completed is its record's, not its images'
    cfg = shipped_variant(tmp_path, "simulated_dome.toml", SMALL)
    stopped = tmp_path / "stopped"
    request = NewSessionRequest(cfg, stopped, lights=12)
    # cancelled once image 8 is committed, as a Ctrl-C in `run` does
    assert cut_new_session(request, after_step=7).finish_reason is FinishReason.CANCELLED
    qa = _qa_json(stopped, tmp_path / "fit_stopped")
    assert qa["session_complete"] is False, qa["verdict"]
    assert any("the session is not finished (8 of 12 images" in c for c in qa["caveats"])

    complete = tmp_path / "complete"
    r = CliRunner().invoke(
        app, ["run", str(cfg), "--out", str(complete), "--lights", "8", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    assert _qa_json(complete, tmp_path / "fit_complete")["session_complete"] is True

    # the same images and .lp without the session's record: nothing to say it either way
    bare = tmp_path / "bare"
    bare.mkdir()
    for path in complete.glob("image_*.jpg"):
        shutil.copy(path, bare / path.name)
    shutil.copytree(complete / "linear", bare / "linear")
    shutil.copy(complete / "lights.lp", bare / "lights.lp")
    assert _qa_json(bare / "lights.lp", tmp_path / "fit_bare")["session_complete"] is None
