"""``rti-rig plan PREVIEW`` without ``--rig`` plans for the rig the preview's session was shot on.

It had planned for the shipped simulated 48-LED dome in silence, its advice naming that dome,
though the preview session's manifest records the rig config it was shot on; the mismatch
showed only when ``run`` refused the plan ("no LED of this dome within 1° … replan"). A
recorded config gone, or whose lights are no longer where the session recorded them, is
refused naming it; a bare image is planned for the simulated dome, with a note saying so.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import REPO, SMALL_DOME, said, write_config
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

runner = CliRunner()
IMAGE = REPO / "tests" / "data" / "neuralrti" / "image11_small.jpg"


def _preview(tmp_path: Path) -> tuple[Path, Path]:
    """A preview session shot on a 12-LED dome (not the shipped 48-LED one): (config, session)."""
    cfg = write_config(tmp_path, SMALL_DOME, "small rig.toml")
    session = tmp_path / "preview"
    r = runner.invoke(app, ["preview", str(cfg), "--out", str(session)])
    assert r.exit_code == 0, r.output
    return cfg, session


def _plan(tmp_path: Path, *args: str) -> tuple[int, str, Path]:
    out = tmp_path / "p.lp"
    r = runner.invoke(app, ["plan", *args, "--lights", "6", "--out", str(out), "--force"])
    return r.exit_code, said(r), out


@pytest.mark.e2e
@pytest.mark.parametrize("what", ["session", "image", "linear image"])
def test_a_preview_of_a_session_is_planned_for_its_rig(tmp_path: Path, what: str) -> None:
    cfg, session = _preview(tmp_path)
    preview = {
        "session": session,
        "image": session / "image_001.jpg",
        "linear image": session / "linear" / "image_001.tif",
    }[what]

    code, text, out = _plan(tmp_path, str(preview))

    assert code == 0, text
    assert (
        f"planning for the rig the preview was shot on: {cfg} (from "
        f"{session / 'manifest.json'}); give --rig to plan for another"
    ) in text, text
    # not a bare "48": pytest's folder (…/pytest-248/…) and the figures may hold one
    assert "on a dome of 12 LEDs" in text, text
    assert not any(s in text for s in ("48 LED", "48-LED", "of 48")), text
    assert "simulated_dome.toml" not in text, text  # the advice names the preview's rig
    # the plan runs on that rig (run refuses lights no LED of the dome is within 1° of)
    run_out = tmp_path / "run"
    r = runner.invoke(app, ["run", str(cfg), "--plan", str(out), "--out", str(run_out)])
    assert r.exit_code == 0, r.output
    assert len(read_lp(out)) == 6


@pytest.mark.e2e
def test_rig_given_is_planned_for_without_the_note(tmp_path: Path) -> None:
    _, session = _preview(tmp_path)

    code, text, _ = _plan(
        tmp_path, str(session), "--rig", str(REPO / "rig_configs/simulated_dome.toml")
    )

    assert code == 0, text
    assert "on a dome of 48 LEDs" in text and "the preview was shot on" not in text, text


@pytest.mark.e2e
def test_a_recorded_rig_that_is_gone_is_refused_naming_it(tmp_path: Path) -> None:
    cfg, session = _preview(tmp_path)
    cfg.unlink()

    code, text, out = _plan(tmp_path, str(session))

    assert code == 2, text
    assert (
        f"{session / 'manifest.json'}: the preview was shot on the rig {cfg}, which is not "
        "there any more (moved or renamed?): give --rig with its path now (or another rig's) "
        "to plan for it"
    ) in text, text
    assert "Traceback" not in text and not out.exists(), text


@pytest.mark.e2e
def test_a_recorded_rig_whose_lights_moved_is_refused(tmp_path: Path) -> None:
    cfg, session = _preview(tmp_path)
    cfg.write_text(SMALL_DOME.replace("azimuth_offset_deg = 45.0", "azimuth_offset_deg = 30.0"))

    code, text, out = _plan(tmp_path, str(session / "image_001.jpg"))

    assert code == 2, text
    assert (
        f"{session / 'manifest.json'}: the rig the preview was shot on, {cfg}, is no longer "
        "the rig it recorded (light positions: 4 of 12 LEDs moved"
    ) in text, text
    assert f"give --rig to say which rig to plan for (--rig '{cfg}' to plan for it" in text, text
    assert not out.exists()


@pytest.mark.e2e
def test_a_recorded_rig_changed_in_its_camera_only_is_planned_for(tmp_path: Path) -> None:
    """The plan is made of where the lights are: a new exposure is not another rig for it."""
    cfg, session = _preview(tmp_path)
    cfg.write_text(SMALL_DOME.replace("exposure_s = 0.05", "exposure_s = 0.08"))

    code, text, _ = _plan(tmp_path, str(session))

    assert code == 0, text
    assert f"planning for the rig the preview was shot on: {cfg}" in text, text


@pytest.mark.e2e
def test_a_bare_image_says_which_rig_it_is_planned_for(tmp_path: Path) -> None:
    code, text, _ = _plan(tmp_path, str(IMAGE))

    assert code == 0, text
    assert (
        f"the preview {IMAGE} is not from an rti-rig session (no manifest.json beside "
        "it), so nothing says which rig it was shot on: planning for rti-rig's simulated dome, "
    ) in text, text
    assert "simulated_dome.toml; give --rig RIG.toml to plan for your rig" in text, text


def test_no_preview_and_no_rig_says_which_rig_it_is_planned_for(tmp_path: Path) -> None:
    code, text, _ = _plan(tmp_path)

    assert code == 0, text
    assert "no --rig given and no preview: planning for rti-rig's simulated dome, " in text, text
