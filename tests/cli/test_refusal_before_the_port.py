"""A `run` refused before the dome's port opens says nothing was lit, not "check the lights".

``rti-rig run`` on the shipped emulated domes with too little free disk under ``--out``: the
refusal comes before the port is opened, so nothing can be lit. It had said "No all-off was
attempted (the dome was never reached): check the dome's lights" above the disk error, sending
a user to a dome the run never touched. The refusal now comes before the rig is even built
(tests/cli/test_disk_refusal_before_the_bar.py): the disk error alone, nothing said of lights.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


@pytest.mark.parametrize("config", ["emulated_dome_card.toml", "emulated_dome.toml"])
def test_a_disk_refusal_before_the_port_opens_sends_no_one_to_the_lights(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, config: str
) -> None:
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda _p: usage._replace(free=1_000_000))
    out = tmp_path / "s"
    r = runner.invoke(app, ["run", str(CONFIGS / config), "--out", str(out)])
    text = said(r)
    assert r.exit_code == 2, text
    assert "not enough free disk space" in text, text
    assert not re.search(r"\blit\b|all-off|switched off", text), text
    assert "check the dome's lights" not in text and "never reached" not in text, text
    assert "Traceback" not in text and not out.exists()
