"""A raking-light session (``--plan`` lights at one azimuth, ``--allow-no-normals``) resumed
with ``--allow-no-normals``.

Before: ``run --resume S --allow-no-normals`` was planned as a new session with no --lights
would be, the rig's default layout, and refused ("the default lights gives a homogeneous
layout of 24; the session ran a plan"), though the flag chooses no light and the session had
it. A flag that chooses no light is now compared with what the session recorded of it alone.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, cut_new_session, said
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.core.lp_format import LpEntry, write_lp
from rti_rig.runtime.controller import FinishReason

runner = CliRunner()
ARM = CONFIGS / "virtual_arm.toml"


def _one_azimuth(path: Path) -> Path:
    """8 lights at azimuth 0°, elevations 15-80°: raking light from one side."""
    el = np.radians(np.linspace(15, 80, 8))
    write_lp(path, [LpEntry(f"i{k}.jpg", (np.cos(e), 0.0, np.sin(e))) for k, e in enumerate(el)])
    return path


def _tree(folder: Path) -> dict[str, str]:
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.fixture()
def raking(tmp_path: Path) -> tuple[Path, Path]:
    """The plan and a session of it with --allow-no-normals, stopped after 3 images."""
    plan = _one_azimuth(tmp_path / "one_az.lp")
    out = tmp_path / "s"
    request = NewSessionRequest(ARM, out, plan=plan, allow_no_normals=True)
    assert cut_new_session(request, after_step=2).finish_reason is FinishReason.CANCELLED
    return plan, out


def test_resume_with_allow_no_normals_alone_continues_the_session(
    raking: tuple[Path, Path],
) -> None:
    _, out = raking
    r = runner.invoke(
        app, ["run", str(ARM), "--resume", str(out), "--allow-no-normals", "--no-verdict"]
    )
    assert r.exit_code == 0, r.output
    assert "3 of 8 images verified on disk" in said(r), said(r)
    assert len(list(out.glob("image_*.jpg"))) == 8


def test_the_line_that_began_it_continues_it(raking: tuple[Path, Path]) -> None:
    plan, out = raking
    line = ["run", str(ARM), "--plan", str(plan), "--allow-no-normals", "--resume", str(out)]
    r = runner.invoke(app, [*line, "--no-verdict"])
    assert r.exit_code == 0, r.output
    assert len(list(out.glob("image_*.jpg"))) == 8


def test_allow_no_normals_on_a_session_shot_without_it_is_refused(tmp_path: Path) -> None:
    """The flag alone is still compared with the session's: a session that could determine
    normals, resumed with it, is told the flag is not the session's, nothing changed."""
    out = tmp_path / "s"
    dome = CONFIGS / "simulated_dome.toml"
    run = cut_new_session(NewSessionRequest(dome, out, lights=8), after_step=1)
    assert run.finish_reason is FinishReason.CANCELLED
    before = _tree(out)
    r = runner.invoke(app, ["run", str(dome), "--resume", str(out), "--allow-no-normals"])
    assert r.exit_code == 2, r.output
    assert "--allow-no-normals given; the session had not" in said(r), said(r)
    assert "the default lights gives" not in said(r)  # no layout was asked, none compared
    assert _tree(out) == before
