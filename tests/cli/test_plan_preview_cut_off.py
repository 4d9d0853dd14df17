"""``rti-rig plan`` reads a cut-off session's preview light from what the session recorded.

A session's manifest lists its steps only when a run ends: a session stopped after 3 images
and resumed, the resume killed after image 10, lists 3 steps while its journal records 10,
each with the light that fired. The images past the manifest's had their light estimated
from the image (25° off on the shipped dome), with no word. And a session folder given with
``--preview-light`` was refused when its record of the light could not be read, with advice to
give ``--preview-light``.
"""

from __future__ import annotations

import json
import shutil
import signal
import time
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app
from rti_rig.core.geometry import az_el_from_direction
from rti_rig.testing.kill_hooks import popen_argv

runner = CliRunner()
CONFIG = CONFIGS / "simulated_dome.toml"


def _journaled(out: Path, image: str) -> dict:  # type: ignore[type-arg]
    """The journal's record of ``image``."""
    lines = (out / "journal.jsonl").read_text().splitlines()
    return next(r for r in map(json.loads, lines) if r["image"] == image)


def _said_light(record: dict) -> str:  # type: ignore[type-arg]
    """How plan prints the light ``record`` says fired."""
    az, el = (float(v) for v in az_el_from_direction(record["actual_direction"]))
    return f"preview light az {az:.1f}°, el {el:.1f}°"


def _stopped_then_resume_killed(tmp_path: Path) -> Path:
    """A 12-light session stopped after its third image (SIGTERM: its manifest lists 3
    steps), resumed, and the resume killed (SIGKILL) after its tenth image was journaled."""
    out = tmp_path / "s"
    proc = popen_argv("stall", 3, ["run", str(CONFIG), "--out", str(out), "--lights", "12"])
    journal = out / "journal.jsonl"
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and proc.poll() is None:
        if journal.exists() and journal.read_text().count("\n") >= 3:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=240)
    assert proc.returncode == 143, stderr.decode()
    assert len(json.loads((out / "manifest.json").read_text())["steps"]) == 3
    proc = popen_argv("after_journal", 6, ["run", "--resume", str(out)])
    _, stderr = proc.communicate(timeout=240)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    assert journal.read_text().count("\n") == 10
    assert len(json.loads((out / "manifest.json").read_text())["steps"]) == 3
    return out


@pytest.mark.e2e
def test_an_image_the_manifest_does_not_list_takes_its_journaled_light(tmp_path: Path) -> None:
    out = _stopped_then_resume_killed(tmp_path)
    plan = ["--rig", str(CONFIG), "--lights", "6", "--out", str(tmp_path / "p.lp"), "--force"]
    for image in ("image_009.jpg", "linear/image_009.tif", "image_002.jpg"):
        r = runner.invoke(app, ["plan", str(out / image), *plan])
        assert r.exit_code == 0, r.output
        record = _journaled(out, f"{Path(image).stem}.jpg")
        assert f"{_said_light(record)} (recorded by the session s)" in said(r), r.output
    # an image the journal alone records, changed since: which shot it is, is not known, so
    # its light is neither taken from the record nor estimated in silence
    shutil.copy(out / "image_002.jpg", out / "image_009.jpg")
    r = runner.invoke(app, ["plan", str(out / "image_009.jpg"), *plan])
    assert r.exit_code == 2, r.output
    assert "is not as the session" in said(r) and "--preview-light AZ,EL" in said(r)
    assert "Traceback" not in r.output
    r = runner.invoke(app, ["plan", str(out / "image_009.jpg"), "--preview-light", "0,45", *plan])
    assert r.exit_code == 0 and "az 0.0°, el 45.0° (given)" in said(r), r.output


@pytest.mark.e2e
def test_a_cut_off_preview_session_plans_with_the_light_given(tmp_path: Path) -> None:
    out = tmp_path / "shot"
    proc = popen_argv("after_journal", 0, ["preview", str(CONFIG), "--out", str(out)])
    _, stderr = proc.communicate(timeout=240)
    assert proc.returncode == -signal.SIGKILL, stderr.decode()
    plan = ["--rig", str(CONFIG), "--lights", "6", "--out", str(tmp_path / "p.lp"), "--force"]
    r = runner.invoke(app, ["plan", str(out), *plan])
    assert r.exit_code == 0, r.output
    assert f"{_said_light(_journaled(out, 'image_001.jpg'))} (recorded by" in said(r), r.output
    # its image changed since its record: the record is not read when the light is given (it
    # had been refused, with advice to give the light that was given)
    tiff = out / "linear" / "image_001.tif"
    tiff.write_bytes(tiff.read_bytes()[:-1] + bytes([tiff.read_bytes()[-1] ^ 1]))
    r = runner.invoke(app, ["plan", str(out), *plan])
    assert r.exit_code == 2 and "is not as the session" in said(r), r.output
    r = runner.invoke(app, ["plan", str(out), "--preview-light", "0,45", *plan])
    assert r.exit_code == 0 and "az 0.0°, el 45.0° (given)" in said(r), r.output
    # no image recorded at all: the advice is not to give the light already given
    (out / "journal.jsonl").write_bytes(b"")
    shutil.rmtree(out / "records")
    r = runner.invoke(app, ["plan", str(out), "--preview-light", "0,45", *plan])
    assert r.exit_code == 2 and "no finished images" in said(r), r.output
    assert "--preview-light" not in said(r)
