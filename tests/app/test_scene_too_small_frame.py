"""A simulated camera frame too small for its scene is refused when the config loads.

`[camera] width = 1` on the relief started a session and stopped at its first capture with
"unexpected ValueError: Shape of array too small to calculate a numerical gradient ... please
report it"; a library scene below 8 x 8 px said only "scene 'tablet': size 6x6 too small".
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import SMALL_DOME, write_config
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize(
    ("scene", "width", "height", "least"),
    [("relief", 1, 64, 2), ("relief", 64, 1, 2), ("tablet", 6, 6, 8), ("coin", 64, 7, 8)],
)
def test_a_frame_too_small_for_the_scene_is_refused_naming_the_keys(
    tmp_path: Path, scene: str, width: int, height: int, least: int
) -> None:
    text = SMALL_DOME.replace("width = 64\nheight = 64", f"width = {width}\nheight = {height}")
    cfg = write_config(tmp_path, text.replace("seed = 3", f'seed = 3\nname = "{scene}"'))
    r = runner.invoke(app, ["run", str(cfg), "--out", str(tmp_path / "s"), "--lights", "3"])
    assert r.exit_code == 2, r.output
    said = " ".join(r.output.split())
    assert "rig.toml" in said and f"camera.width x camera.height = {width} x {height}" in said
    assert f"at least {least} x {least} px" in said and "unexpected" not in said, said
    assert not (tmp_path / "s").exists()


def test_the_smallest_frames_still_run(tmp_path: Path) -> None:
    for scene, side in (("relief", 2), ("tablet", 8)):
        text = SMALL_DOME.replace("width = 64\nheight = 64", f"width = {side}\nheight = {side}")
        cfg = write_config(tmp_path, text.replace("seed = 3", f'seed = 3\nname = "{scene}"'))
        out = tmp_path / scene
        r = runner.invoke(
            app, ["run", str(cfg), "--out", str(out), "--lights", "3", "--no-verdict"]
        )
        assert r.exit_code == 0, r.output
        assert len(list(out.glob("image_*.jpg"))) == 3
