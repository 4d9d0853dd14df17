"""`rti-rig plan PREVIEW --preview-light AZ,EL` says when the light given is not the one the
preview's session recorded.

Why: the given light wins, and the relief is read from the preview's shading as that light would
make it. On the shipped simulated dome, `rti-rig preview` fires the LED nearest 135,50 in the
45–60° band (az 112.5°, el 55.0°, 14.5° away); planning from that preview with
`--preview-light 135,50` used a light 14.5° off the one that fired and said only "(given)".
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()
RIG = CONFIGS / "simulated_dome.toml"


def _preview(tmp_path: Path) -> Path:
    session = tmp_path / "preview é"
    r = runner.invoke(app, ["preview", str(RIG), "--out", str(session)])
    assert r.exit_code == 0, r.output
    return session


def _plan(tmp_path: Path, preview: Path, light: str) -> str:
    out = tmp_path / f"plan {light}.lp"
    r = runner.invoke(
        app,
        ["plan", str(preview), "--rig", str(RIG), "--preview-light", light, "--out", str(out)],
    )
    assert r.exit_code == 0, r.output
    assert out.is_file()
    return said(r)


def test_a_given_light_off_the_recorded_one_is_said_with_both(tmp_path: Path) -> None:
    session = _preview(tmp_path)

    text = _plan(tmp_path, session, "135,50")

    assert "preview light az 135.0°, el 50.0° (given)" in text, text
    assert (
        "--preview-light 135,50 is 14.5° from the light recorded by the session preview é "
        "(az 112.5°, el 55.0°): the plan used the light given; leave --preview-light out"
    ) in text, text


def test_a_given_light_that_is_the_recorded_one_says_nothing_more(tmp_path: Path) -> None:
    session = _preview(tmp_path)

    text = _plan(tmp_path, session / "image_001.jpg", "112.5,55")

    assert "(given)" in text, text
    assert "from the light recorded" not in text, text


def test_a_record_that_cannot_be_read_leaves_the_given_light_alone(tmp_path: Path) -> None:
    """The note reads the session's record at its best: a step recorded without its light (a
    manifest damaged or edited, no journal beside it) had raised a KeyError out of plan, where
    the light given had always stood in for the record."""
    import json
    import shutil

    session = _preview(tmp_path)
    (session / "journal.jsonl").unlink()
    shutil.rmtree(session / "records", ignore_errors=True)
    manifest = json.loads((session / "manifest.json").read_text())
    del manifest["steps"][0]["actual_direction"]
    (session / "manifest.json").write_text(json.dumps(manifest))

    text = _plan(tmp_path, session, "112.5,55")

    assert "(given)" in text, text
    assert "from the light recorded" not in text, text
