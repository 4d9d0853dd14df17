"""A refusal of ``[camera.device]`` or ``[camera.device.decode]`` names the config as given.

Those tables are checked once the config is loaded, from its resolved path, so ``rti-rig check
my.toml`` said ``/abs/…/my.toml: key 'camera.device.bogus'`` where every other table says
``my.toml: key '…'``. (``dome.lp_file`` had the same slip.)
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import at_key
from typer.testing import CliRunner

from rti_rig.cli import app

REPO = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("config", ["example_dome_48.toml", "example_dome_48_folder_watch.toml"])
@pytest.mark.parametrize(
    ("table", "line", "key"),
    [
        ("[camera.device]", "bogus = 1", "camera.device.bogus"),
        ("[camera.device.decode]", "bogus = 1", "camera.device.decode.bogus"),
        ("[dome]", 'lp_file = "nothere.lp"', "dome.lp_file"),
    ],
)
def test_a_refused_key_names_the_config_as_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, config: str, table: str, line: str, key: str
) -> None:
    shutil.copy(REPO / "rig_configs" / "example_dome_48.lp", tmp_path)
    text = (REPO / "rig_configs" / config).read_text(encoding="utf-8")
    if line.startswith("lp_file"):
        text = text.replace('lp_file = "example_dome_48.lp"', line)
    else:
        text = text.replace(f"{table}\n", f"{table}\n{line}\n", 1)
    (tmp_path / "my.toml").write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(app, ["check", "my.toml"])
    said = " ".join(r.output.split())
    assert r.exit_code == 2, said
    assert f"error: {at_key('my.toml', key, tmp_path / 'my.toml')}:" in said, said
    assert "error: my.toml, line " in said, said  # each of these keys is written in the file
    assert f"{tmp_path / 'my.toml'}" not in said
    assert "Traceback" not in said
