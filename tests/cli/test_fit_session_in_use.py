"""``fit``, ``export-lp``, ``plan`` and ``check`` of a session another rti-rig process is
still capturing.

The fit read the session's lights.lp and its images at different moments while they grew:
"error: 40 image names for 33 light directions", or a verdict of part of the session that
advised a ``--resume`` the running capture would refuse. ``plan`` from such a session (or one
of its images) said it had "no finished images" and advised that refused ``--resume`` too. All
are now refused, saying why and when to come back; once that run has ended they read the
session as ever.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from conftest import REPO, SMALL_DOME, line_within, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

runner = CliRunner()

#: holds a session's lock as a capturing run does, until its stdin closes
HOLDER = """
import sys
from rti_rig.runtime.session import lock_session
lock_session(sys.argv[1])
print("locked", flush=True)
sys.stdin.read()
"""


def test_a_session_being_captured_is_not_fitted_or_exported(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), "--lights", "8", "--no-verdict"])
    assert r.exit_code == 0, r.output
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLDER, str(s)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        env=env,
        text=True,
    )
    try:
        assert line_within(holder, 120, "the lock holder's 'locked'").strip() == "locked"
        for args in (["fit", str(s)], ["fit", str(s / "lights.lp")]):
            r = runner.invoke(app, [*args, "--out", str(tmp_path / "fit")])
            assert r.exit_code == 2, r.output
            assert "being captured by another rti-rig process" in said(r)
            assert "fit it once that run has ended" in said(r)
            assert not (tmp_path / "fit").exists()
        r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "x.lp")])
        assert r.exit_code == 2 and "being captured" in said(r), r.output
        # it had read "export its .lp it once that run has ended"
        assert "export its .lp once that run has ended" in said(r), r.output
        # check of its lights.lp as a replay had passed the images present so far
        r = runner.invoke(app, ["check", str(s / "lights.lp")])
        assert r.exit_code == 2 and "being captured" in said(r), r.output
        assert "check its images once that run has ended" in said(r), r.output
        assert "RESULT" not in said(r), r.output
        # as a replay rig, a plan's rig and a trade's acquisition: they had read the images
        # so far as a whole acquisition, in silence
        lp = str(s / "lights.lp")
        for args in (
            ["run", lp, "--out", str(tmp_path / "replay"), "--lights", "6"],
            ["plan", "--rig", lp, "--lights", "6", "--out", str(tmp_path / "p.lp")],
            ["bench", "tradeoff", "--from", lp, "--out", str(tmp_path / "bench")],
        ):
            r = runner.invoke(app, args)
            assert r.exit_code == 2 and "being captured" in said(r), (args[0], r.output)
            assert "once that run has ended" in said(r), r.output
        assert not (tmp_path / "replay").exists() and not (tmp_path / "bench").exists()
    finally:
        assert holder.stdin is not None
        holder.stdin.close()
        holder.wait(timeout=60)
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["check", str(s / "lights.lp")])
    assert r.exit_code == 0 and "RESULT: PASS" in r.output, r.output


def test_a_session_being_captured_is_not_planned_from(tmp_path: Path) -> None:
    cfg = write_config(tmp_path, SMALL_DOME)
    s = tmp_path / "s"
    r = runner.invoke(app, ["run", str(cfg), "--out", str(s), "--lights", "3", "--no-verdict"])
    assert r.exit_code == 0, r.output
    # its manifest as a capture under way has it: steps are listed when the run ends
    manifest = json.loads((s / "manifest.json").read_text())
    for key in ("finished_at", "timing", "lp_file", "notices"):
        manifest.pop(key)
    manifest["runner"] = {"state": "running", "finish_reason": None}
    manifest["steps"] = []
    (s / "manifest.json").write_text(json.dumps(manifest))
    plan = tmp_path / "p.lp"
    args = ["--rig", str(cfg), "--lights", "6", "--out", str(plan)]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLDER, str(s)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        env=env,
        text=True,
    )
    try:
        assert line_within(holder, 120, "the lock holder's 'locked'").strip() == "locked"
        for preview in (s, s / "image_002.jpg", s / "linear" / "image_002.tif"):
            r = runner.invoke(app, ["plan", str(preview), *args])
            assert r.exit_code == 2, r.output
            assert "being captured by another rti-rig process" in said(r)
            assert "plan from it once that run has ended" in said(r)
            assert "--resume" not in said(r) and "no finished images" not in said(r)
            assert not plan.exists()
    finally:
        assert holder.stdin is not None
        holder.stdin.close()
        holder.wait(timeout=60)
    # the run gone (killed: its manifest still as it began), its journal records the light
    # (tests/cli/test_plan_preview_cut_off.py)
    r = runner.invoke(app, ["plan", str(s / "image_002.jpg"), *args])
    assert r.exit_code == 0 and "(recorded by the session s)" in r.output, r.output
    assert len(read_lp(plan)) == 6
