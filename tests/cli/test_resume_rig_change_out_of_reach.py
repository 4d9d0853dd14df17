"""``run --resume --accept-rig-change`` on an arm whose reach the change narrowed, leaving the
session's own remaining lights out of it.

Found by a front-door audit: the resume listed the steps it could not run ("step 4: elevation
... is above the arm's maximum 40°"; on a Dynamixel arm "azimuth 329.342 deg is outside the
joint limits -10.0..170.0") and stopped there, with nothing on what to do: the session's lights
are fixed when it begins, so only the rig as it began finishes it, or a new session runs on
the rig as it is.
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, cut_new_session
from typer.testing import CliRunner

from rti_rig.app.usecases.session import NewSessionRequest
from rti_rig.cli import app
from rti_rig.runtime.controller import FinishReason

runner = CliRunner()


def test_a_narrowed_reach_accepted_on_resume_says_how_to_go_on(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    text = (CONFIGS / "virtual_arm.toml").read_text()
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text.replace("width = 512", "width = 64").replace("height = 512", "height = 64"))
    out = tmp_path / "s"
    result = cut_new_session(NewSessionRequest(cfg, out, lights=6), after_step=1)
    assert result.finish_reason is FinishReason.CANCELLED
    before = sorted(p.relative_to(out).as_posix() for p in out.rglob("*"))
    cfg.write_text(cfg.read_text().replace("max_elevation_deg = 80.0", "max_elevation_deg = 40.0"))

    r = runner.invoke(app, ["run", "--resume", "s", "--accept-rig-change", "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "is above the arm's maximum 40°" in said, said
    assert "leaves these steps of s unable to run on it: to finish the session, set" in said, said
    assert "s/manifest.json, under rig.config) and resume" in said, said
    command = said.split("or shoot a new session on the rig as it is: ", 1)[1]
    assert command == f"rti-rig run {shlex.quote(str(cfg))} --out s-again", said
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == before  # untouched

    r = runner.invoke(app, [*shlex.split(command)[1:], "--lights", "6", "--no-verdict"])
    assert r.exit_code == 0, r.output


def test_a_dynamixel_arm_s_azimuth_out_of_its_new_limits_is_said_in_their_terms(
    tmp_path: Path,
) -> None:
    """The emulated Dynamixel arm, its azimuth joint narrowed to -10..170°: a light at azimuth
    -30.7° was said as "azimuth 329.342 deg is outside the joint limits -10.0..170.0"."""
    text = (CONFIGS / "simulated_arm.toml").read_text()
    text = text.replace('transport = "pty"', 'transport = "inprocess"')
    text = text.replace("width = 256", "width = 32").replace("height = 256", "height = 32")
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text)
    out = tmp_path / "s"
    result = cut_new_session(NewSessionRequest(cfg, out, lights=6), after_step=1)
    assert result.finish_reason is FinishReason.CANCELLED
    cfg.write_text(text.replace("min_deg = -170.0", "min_deg = -10.0"))

    r = runner.invoke(app, ["run", "--resume", str(out), "--accept-rig-change", "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert "azimuth -30.658 deg is outside the joint limits -10.0..170.0" in said, said
    assert "329.342" not in said, said
    assert "leaves these steps of" in said and "--out " in said, said


def test_a_reach_narrowed_only_where_images_were_shot_resumes_keeping_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The arm's band narrowed to 20..60° after 4 of 6 images (shot at 37.7°, 18.2°, 9.3° and
    65.5°; the two left at 27.5° and 49.5°): before, the resume checked the whole schedule and
    refused steps 2-4, already on disk. The steps left are checked, the ones shot kept, said
    and recorded as shot on the rig as it was, and lights.lp lists the lights that fired."""
    import json

    monkeypatch.chdir(tmp_path)
    text = (CONFIGS / "virtual_arm.toml").read_text()
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text.replace("width = 512", "width = 64").replace("height = 512", "height = 64"))
    out = tmp_path / "s"
    result = cut_new_session(NewSessionRequest(cfg, out, lights=6), after_step=3)
    assert result.finish_reason is FinishReason.CANCELLED
    lp_before = (out / "lights.lp").read_text().splitlines()
    assert len(lp_before) == 5  # its count, then the four images shot
    narrowed = cfg.read_text().replace("min_elevation_deg = 5.0", "min_elevation_deg = 20.0")
    cfg.write_text(narrowed.replace("max_elevation_deg = 80.0", "max_elevation_deg = 60.0"))

    r = runner.invoke(app, ["run", "--resume", "s", "--accept-rig-change", "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "3 image(s) already shot could not be taken on the rig as changed (step 2" in said, said
    assert "they are kept, shot on the rig as it was" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed", manifest["runner"]
    kept = manifest["runs"][-1]["shot_before_rig_change"]["steps"]
    assert [line.split(" ", 2)[1] for line in kept] == ["2:", "3:", "4:"], kept
    lp = (out / "lights.lp").read_text().splitlines()
    assert lp[0].strip() == "6" and lp[1:5] == lp_before[1:], lp  # the lights that fired


def _adaptive_cut_then_narrowed(
    tmp_path: Path, after_step: int, copy: Path | None = None
) -> list[dict[str, Any]]:
    """``run --adaptive`` of 8 lights on the virtual arm (64 px frames) into ``tmp_path/s``,
    cut after step ``after_step``, copied to ``copy`` if given; then the config's reach
    narrowed from 5..80° to 25..50°. The journal's records of the steps shot."""
    import shutil

    from conftest import journal

    text = (CONFIGS / "virtual_arm.toml").read_text()
    cfg = tmp_path / "arm.toml"
    cfg.write_text(text.replace("width = 512", "width = 64").replace("height = 512", "height = 64"))
    out = tmp_path / "s"
    request = NewSessionRequest(cfg, out, lights=8, adaptive=True)
    assert cut_new_session(request, after_step=after_step).finish_reason is FinishReason.CANCELLED
    if copy is not None:
        shutil.copytree(out, copy)
    narrowed = cfg.read_text().replace("min_elevation_deg = 5.0", "min_elevation_deg = 25.0")
    cfg.write_text(narrowed.replace("max_elevation_deg = 80.0", "max_elevation_deg = 50.0"))
    return journal(out)


def test_an_adaptive_session_narrowed_where_it_shot_resumes_keeping_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``run --adaptive`` on the arm, cut after 5 of 8 lights (its start at 14.4°, 20.7°,
    21.1°, 53.3°, then one chosen at 51.2°), the reach narrowed to 25..50°: before, the resume
    checked the whole starting layout and refused steps 1-4, already on disk, where a planned
    session's resume keeps them. The lights shot are kept and said, the rest is chosen within
    the new reach, and the choice is deterministic: a copy resumed, cut again and resumed with
    no flag (which re-decides the steps taken since the change, and refuses any decided
    otherwise) ends with the same lights."""
    import json

    import numpy as np
    from conftest import decisions, journal

    from rti_rig.app.usecases.session import ResumeRequest, open_resumed_session
    from rti_rig.app.usecases.session import run_opened_session as run_it
    from rti_rig.runtime.controller import CancelToken, StepCompleted

    monkeypatch.chdir(tmp_path)
    out = tmp_path / "s"
    shot = _adaptive_cut_then_narrowed(tmp_path, after_step=4, copy=tmp_path / "copy")

    r = runner.invoke(app, ["run", "--resume", "s", "--accept-rig-change", "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "5 image(s) already shot could not be taken on the rig as changed (step 1" in said
    assert "step 5: elevation 51.18° is above the arm's maximum 50°" in said, said
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["runner"]["finish_reason"] == "completed", manifest["runner"]
    assert len(manifest["runs"][-1]["shot_before_rig_change"]["steps"]) == 5
    steps = journal(out)
    assert len(steps) == 8 and steps[:5] == shot  # kept as recorded
    elevations = np.degrees(np.arcsin([s["planned_direction"][2] for s in steps[5:]]))
    assert np.all((elevations >= 25.0) & (elevations <= 50.0)), elevations

    cancel = CancelToken()  # the copy: accepted, cut after one light more, resumed again

    def cut(event: object) -> None:
        if isinstance(event, StepCompleted) and event.index == 5:
            cancel.cancel()

    copy = tmp_path / "copy"
    run_it(open_resumed_session(ResumeRequest(copy, accept_rig_change=True)), cancel, cut)
    r = runner.invoke(app, ["run", "--resume", "copy", "--no-verdict"])
    assert r.exit_code == 0, r.output
    again = journal(copy)
    key = [(s["led"], s["planned_direction"]) for s in steps]
    assert [(s["led"], s["planned_direction"]) for s in again] == key
    assert decisions(copy) == decisions(out)


def test_an_adaptive_start_left_to_shoot_is_placed_on_the_narrowed_reach(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same session cut within its start (3 of its 4 lights shot; the fourth recorded at
    53.3°), the reach narrowed to 25..50°: the resume places what is left of the start on the
    arm as it is now, and had refused the recorded 53.3°, a light it would not have taken."""
    import json

    import numpy as np
    from conftest import journal

    monkeypatch.chdir(tmp_path)
    out = tmp_path / "s"
    shot = _adaptive_cut_then_narrowed(tmp_path, after_step=2)

    r = runner.invoke(app, ["run", "--resume", "s", "--accept-rig-change", "--no-verdict"])
    said = " ".join(r.output.split())
    assert r.exit_code == 0, said
    assert "53.28" not in said, said
    assert "3 image(s) already shot could not be taken on the rig as changed (step 1" in said
    steps = journal(out)
    assert len(steps) == 8 and steps[:3] == shot
    elevations = np.degrees(np.arcsin([s["planned_direction"][2] for s in steps[3:]]))
    assert np.all((elevations >= 25.0) & (elevations <= 50.0)), elevations
    # the manifest's schedule is the start as shot (it had kept the 53.3° that never fired);
    # the start recorded before the change is kept in the run
    manifest = json.loads((out / "manifest.json").read_text())
    start = [s["direction"] for s in manifest["schedule"]["steps"]]
    assert start == [s["planned_direction"] for s in steps[:4]], (start, steps[:4])
    before = manifest["runs"][-1]["schedule_before_rig_change"]["steps"]
    assert round(float(np.degrees(np.arcsin(before[3]["direction"][2]))), 1) == 53.3, before
