"""`rti-rig plan PREVIEW` (no --preview-light) on a preview whose session records no light for
its step is refused, naming the file, what is missing and that --preview-light supplies it.

Why: a step of the manifest written without its light (a manifest damaged or edited, no
journal beside it to stand in) raised a KeyError traceback out of plan, where the light the
user can give stands in for it (tests/cli/test_plan_given_light_differs.py).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
RIG = CONFIGS / "simulated_dome.toml"


def _preview_recording(tmp_path: Path, light: Any) -> Path:
    """A one-image preview session, its journal and step records gone and the manifest's step
    giving ``light`` (``...`` for none at all) as the light that fired."""
    session = tmp_path / "preview é"
    r = runner.invoke(app, ["preview", str(RIG), "--out", str(session)])
    assert r.exit_code == 0, r.output
    (session / "journal.jsonl").unlink()
    shutil.rmtree(session / "records", ignore_errors=True)
    manifest = json.loads((session / "manifest.json").read_text())
    if light is ...:
        del manifest["steps"][0]["actual_direction"]
    else:
        manifest["steps"][0]["actual_direction"] = light
    (session / "manifest.json").write_text(json.dumps(manifest))
    return session


@pytest.mark.parametrize("which", ["session", "image_001.jpg", "linear/image_001.tif"])
def test_a_step_recorded_without_its_light_is_refused_naming_the_manifest(
    tmp_path: Path, which: str
) -> None:
    session = _preview_recording(tmp_path, ...)
    preview = session if which == "session" else session / which
    out = tmp_path / "plan.lp"

    r = runner.invoke(app, ["plan", str(preview), "--rig", str(RIG), "--out", str(out)])
    text = said(r)

    assert r.exit_code == 2, text
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "Traceback" not in text and "KeyError" not in text, text
    assert "manifest.json: step 1 (image_001." in text, text
    assert "records no light ('actual_direction' is missing)" in text, text
    assert text.endswith("give it with --preview-light AZ,EL"), text
    assert not out.exists()


def test_a_step_recorded_with_a_light_that_is_no_direction_is_refused(tmp_path: Path) -> None:
    session = _preview_recording(tmp_path, [0.0, 0.0])
    out = tmp_path / "plan.lp"

    r = runner.invoke(app, ["plan", str(session), "--rig", str(RIG), "--out", str(out)])
    text = said(r)

    assert r.exit_code == 2, text
    assert "records the light [0.0, 0.0], not a direction" in text, text
    assert "give it with --preview-light AZ,EL" in text, text
    assert not out.exists()


@pytest.mark.parametrize("light", [[], ["--preview-light", "112.5,55"]])
def test_a_step_recorded_without_its_linear_image_is_refused_naming_the_image_to_give(
    tmp_path: Path, light: list[str]
) -> None:
    """The session folder's one step names its linear image; without it (a manifest damaged or
    edited) plan raised a KeyError, with or without --preview-light."""
    session = _preview_recording(tmp_path, [0.5, 0.2, 0.8])
    manifest = json.loads((session / "manifest.json").read_text())
    del manifest["steps"][0]["linear_image"]
    (session / "manifest.json").write_text(json.dumps(manifest))
    out = tmp_path / "plan.lp"

    r = runner.invoke(app, ["plan", str(session), "--rig", str(RIG), "--out", str(out), *light])
    text = said(r)

    assert r.exit_code == 2, text
    assert "Traceback" not in text and "KeyError" not in text, text
    assert (
        f"{session / 'manifest.json'}: its step records no linear image ('linear_image' is "
        f"missing): give the image itself as PREVIEW ({session / 'image_001.jpg'})"
    ) in text, text
    assert not out.exists()
    given = runner.invoke(
        app, ["plan", str(session / "image_001.jpg"), "--rig", str(RIG), "--out", str(out)]
    )
    assert given.exit_code == 0, given.output
