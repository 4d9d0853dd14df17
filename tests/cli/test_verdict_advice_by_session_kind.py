"""The QA verdict's advice is one the session can follow, through the front door.

Found by an audit: a replayed acquisition and an adaptive session were both told "reshoot with
less exposure" for a clipped image; a replay cannot be reshot at all, and an adaptive session
cannot reshoot one image (the lights after it were chosen from it).
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import CONFIGS, coin_dome
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.lp_format import read_lp

REPO = Path(__file__).resolve().parents[2]
ACQ = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
runner = CliRunner()


def said(result) -> str:  # type: ignore[no-untyped-def]
    return " ".join(result.output.split())


def test_a_replayed_acquisition_is_not_told_to_reshoot_with_less_exposure(tmp_path: Path) -> None:
    r = runner.invoke(app, ["run", str(ACQ), "--out", str(tmp_path / "s"), "--lights", "9"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "saturated" in text, text  # the recording's own clipped images
    assert "reshoot with less exposure" not in text
    assert "(a replayed acquisition cannot be reshot)" in text
    assert "this session replays a recorded acquisition" in text
    assert "QA verdict: flawed: image_" in text and "QA verdict: reshoot" not in text


def test_a_replay_verdict_names_the_recorded_file_of_each_clipped_image(tmp_path: Path) -> None:
    """The verdict had named the session's images only ("image_006 … clipped in the
    recording"): which of the user's own photographs was clipped was theirs to work out. Each
    clipped image is named with the recorded file it replays, found here by its light."""
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(ACQ), "--out", str(out)])
    assert r.exit_code == 0, r.output
    text = said(r)
    recorded = {e.direction: e.name for e in read_lp(ACQ)}
    clipped = re.findall(r"(image_\d{3}) \(saturated: [^;]*; clipped in the recording", text)
    assert clipped, text
    session = {Path(e.name).stem: e.direction for e in read_lp(out / "lights.lp")}
    for image in clipped:
        light = np.asarray(session[image])
        source = min(recorded, key=lambda d: float(np.sum((np.asarray(d) - light) ** 2)))
        assert (
            f"clipped in the recording, {recorded[source]} (a replayed acquisition cannot be "
            "reshot)" in text
        ), (image, text)


@pytest.mark.pty
def test_an_adaptive_session_is_not_told_to_reshoot_one_image(tmp_path: Path) -> None:
    cfg = coin_dome(tmp_path)  # a polished coin at a fixed 0.05 s: the top clips
    r = runner.invoke(
        app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--adaptive", "--lights", "9"]
    )
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "saturated" in text, text
    assert "reshoot with less exposure" not in text
    assert "a new session with a shorter camera.exposure_s avoids it" in text
    assert "an adaptive session cannot reshoot single images" in text


@pytest.mark.pty
def test_a_planned_session_is_told_it_keeps_one_exposure(tmp_path: Path) -> None:
    """A planned session's clipped images: "reshoot with less exposure" named images no
    command could shoot again so (a resume with another exposure_s is refused, and
    --reshoot-lost reshoots only what is lost); a new session with less exposure is what
    mends them."""
    cfg = coin_dome(tmp_path)
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "48"])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "reshoot with less exposure" not in text and "cannot reshoot" not in text
    assert "a session keeps one exposure: shoot it again as a new session with a shorter " in text
    sed = cfg.read_text().replace("exposure_s = 0.05", "exposure_s = 0.02")
    assert sed != cfg.read_text()
    (tmp_path / "short.toml").write_text(sed)
    r = runner.invoke(app, ["run", str(tmp_path / "short.toml"), "--resume", str(tmp_path / "s")])
    assert r.exit_code == 2 and "exposure" in said(r)  # as the advice says: not by a resume


@pytest.mark.parametrize("lights", [1, 2])
def test_a_test_shot_of_too_few_lights_is_told_what_run_can_do(tmp_path: Path, lights: int) -> None:
    """A session of 1 or 2 lights has no normal map to judge: the verdict's refusal had been
    the fit's own, ending "choose a lower-order model", an option run does not have. It says
    how many lights the verdict needs and the run option that gives them; the run succeeds."""
    out = tmp_path / "s"
    dome = CONFIGS / "simulated_dome.toml"
    r = runner.invoke(app, ["run", str(dome), "--out", str(out), "--lights", str(lights)])
    assert r.exit_code == 0, r.output
    text = said(r)
    assert "lower-order model" not in text
    assert (
        f"QA verdict unavailable: the verdict's normal map needs at least 3 lights and this "
        f"session has {lights}; run with --lights 3 or more" in text
    )
    assert len(list(out.glob("image_*.jpg"))) == lights


def test_a_replay_verdict_names_no_recorded_file_once_the_lp_is_edited(tmp_path: Path) -> None:
    """The recorded files are named from the replayed `.lp` as it is when the verdict is made:
    one edited since the session (here its lines' names reversed) had the verdict name other
    photographs as clipped. The files are named only while the `.lp` and its images are the
    ones the session began with (their recorded digest)."""
    acq = tmp_path / "acq"
    shutil.copytree(ACQ.parent, acq)
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(acq / ACQ.name), "--out", str(out), "--no-verdict"])
    assert r.exit_code == 0, r.output
    lines = (acq / ACQ.name).read_text().splitlines()
    names = [line.split()[0] for line in lines[1:]][::-1]
    edited = [f"{n} {' '.join(line.split()[1:])}" for n, line in zip(names, lines[1:], strict=True)]
    (acq / ACQ.name).write_text("\n".join([lines[0], *edited]) + "\n")

    r = runner.invoke(app, ["fit", str(out), "--out", str(tmp_path / "fit")])
    text = said(r)
    assert r.exit_code == 0, text
    assert "clipped in the recording (a replayed acquisition cannot be reshot)" in text, text
    assert not re.search(r"clipped in the recording, \S+", text), text
