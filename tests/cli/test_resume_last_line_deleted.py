"""The last line of a stopped session's ``lights.lp`` deleted by hand, then ``run --resume``:
the resume had written ``lights.lp`` again from the journal with no copy and no word, taking
the deletion for a run killed between that image's journal line and the rewrite of
``lights.lp`` (the same bytes). A run whose end the manifest records (a Ctrl-C stop) wrote
``lights.lp`` listing every step before recording it, so there the deletion is an edit: kept in
``recovered/STAMP/lights.lp`` and said, as a deletion of any other line is. A kill between the
journal line and ``lights.lp`` is still no edit (tests/cli/test_resume_edited_lights_lp.py).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import CONFIGS, REPO, said
from sigterm_support import signal_at_commit
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.slow
@pytest.mark.e2e
@pytest.mark.skipif(sys.platform == "win32", reason="signals tested on POSIX")
def test_the_last_line_deleted_from_a_stopped_sessions_lights_lp_is_kept_and_said(
    tmp_path: Path,
) -> None:
    out = tmp_path / "s"
    args = ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "6"]
    proc = subprocess.run(  # Ctrl-C as image_003 is committed: the run stops after it
        [sys.executable, "-c", signal_at_commit("SIGINT"), "2", *args, "--no-verdict"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(REPO)},
    )
    assert proc.returncode == 130, proc.stdout + proc.stderr
    lp = out / "lights.lp"
    own = lp.read_text()
    assert own.splitlines()[0] == "3" and "image_003.jpg" in own, own
    untouched = tmp_path / "untouched"
    shutil.copytree(out, untouched)
    edited = "2\n" + "".join(own.splitlines(True)[1:3])  # image_003 left out of the fit
    lp.write_text(edited)

    r = runner.invoke(app, ["run", "--resume", str(out), "--no-verdict"])

    assert r.exit_code == 0, r.output
    (kept,) = sorted((out / "recovered").rglob("lights.lp"))
    assert kept.read_text() == edited
    assert (
        f"{lp} differs from what rti-rig wrote from journal.jsonl (edited by hand?): kept as "
        f"{kept}; lights.lp is written again from the journal"
    ) in said(r), said(r)
    # the same stopped session, its lights.lp as the run left it: nothing kept, nothing said
    r = runner.invoke(app, ["run", "--resume", str(untouched), "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert not (untouched / "recovered").exists() and "edited by hand" not in said(r), said(r)
