"""`rti-rig plan RIG.toml …` (the `--rig` forgotten) says the file is a rig config, and where
it goes.

Found by a front-door audit: `rti-rig plan rig_configs/simulated_dome.toml --lights 8` and
`rti-rig plan ACQ/dirs.lp --lights 8` were told only "cannot read this file as an image (JPEG,
PNG or TIFF)", which does not say that the file is fine, only misplaced.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]
runner = CliRunner()


def _refusal(tmp_path: Path, given: Path) -> str:
    out = tmp_path / "plan.lp"
    r = runner.invoke(app, ["plan", str(given), "--lights", "8", "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert "Traceback" not in text and "cannot read this file as an image" not in text
    assert not out.exists()
    return text


def test_a_rig_config_given_as_the_preview_is_sent_to_rig(tmp_path: Path) -> None:
    config = CONFIGS / "simulated_dome.toml"
    text = _refusal(tmp_path, config)
    assert f"{config} is a rig config, not a preview image: give it as --rig {config}" in text


def test_an_lp_given_as_the_preview_is_sent_to_rig(tmp_path: Path) -> None:
    lp = REPO / "tests" / "data" / "neuralrti_replay" / "dirs.lp"
    text = _refusal(tmp_path, lp)
    assert f"{lp} is an .lp light list, not a preview image: give it as --rig {lp}" in text
    assert "as PREVIEW one of the images it lists" in text
