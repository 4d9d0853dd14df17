"""``fit`` and ``export-lp`` of a session another rti-rig process is still capturing.

The fit read the session's lights.lp and its images at different moments while they grew:
"error: 40 image names for 33 light directions", or a verdict of part of the session that
advised a ``--resume`` the running capture would refuse. Both are now refused, saying why
and when to come back; once that run has ended they read the session as ever.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from conftest import REPO, SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

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
        assert holder.stdout is not None and holder.stdout.readline().strip() == "locked"
        for args in (["fit", str(s)], ["fit", str(s / "lights.lp")]):
            r = runner.invoke(app, [*args, "--out", str(tmp_path / "fit")])
            assert r.exit_code == 2, r.output
            assert "being captured by another rti-rig process" in said(r)
            assert not (tmp_path / "fit").exists()
        r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "x.lp")])
        assert r.exit_code == 2 and "being captured" in said(r), r.output
    finally:
        assert holder.stdin is not None
        holder.stdin.close()
        holder.wait(timeout=60)
    r = runner.invoke(app, ["fit", str(s), "--out", str(tmp_path / "fit")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, ["export-lp", str(s), "--out", str(tmp_path / "x.lp")])
    assert r.exit_code == 0, r.output
