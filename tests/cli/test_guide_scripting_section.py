"""The guide's section for scripts (exit codes, the files to read) names what the code writes.

A shell loop over dozens of parts branches on ``manifest.json``'s ``runner.finish_reason``; the
values were documented nowhere, and a value the guide does not list (or one it lists that the
code never writes) would send a script down the wrong branch. Checked against the code's own
set, and the manifest keys the section names against a session written through the CLI.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from conftest import CONFIGS, REPO
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason
from rti_rig.runtime.session import RUN_ENDED

GUIDE = REPO / "docs" / "guide.md"


def _section() -> str:
    text = GUIDE.read_text(encoding="utf-8")
    found = re.search(r"^## 11\. Scripting.*?(?=^## )", text, re.S | re.M)
    assert found, "the guide's scripting section is gone"
    return found.group(0)


def _finish_reason_bullet() -> str:
    found = re.search(r"^- \*\*`runner\.finish_reason`\*\*(.*?)(?=^- |\Z)", _section(), re.S | re.M)
    assert found, "the section's finish_reason bullet is gone"
    return " ".join(found.group(1).split())


def test_the_guide_lists_every_finish_reason_the_code_writes_and_no_other() -> None:
    bullet = _finish_reason_bullet()
    # the values are the bullet's backticked words up to "Only `completed`"
    listed = set(re.findall(r"`([a-z-]+)`", bullet.split("Only `completed`")[0]))
    written = {str(r) for r in FinishReason} | set(RUN_ENDED)
    assert written <= listed, f"not in the guide: {sorted(written - listed)}"
    assert listed - written <= {"null", "runs"}, f"not written by the code: {listed - written}"


def test_the_manifest_keys_the_guide_names_are_in_a_sessions_manifest(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = CliRunner().invoke(
        app,
        ["run", str(CONFIGS / "simulated_dome.toml"), "--out", str(out), "--lights", "1"],
    )
    assert r.exit_code == 0, r.output
    runner = json.loads((out / "manifest.json").read_text())["runner"]
    named = set(re.findall(r"`runner\.([a-z_]+)`", _section()))
    assert {"finish_reason", "state", "steps_done", "steps_planned", "error"} <= named
    assert named <= set(runner), f"named in the guide, not in the manifest: {named - set(runner)}"
    assert runner["finish_reason"] == "completed" and runner["state"] == "finished"
    assert runner["steps_done"] == runner["steps_planned"] == 1
