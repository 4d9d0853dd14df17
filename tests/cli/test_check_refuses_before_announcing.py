"""``rti-rig check`` refuses an unusable option before it says "Checking …".

``check emulated_rtipy.toml --intensity 0.5`` had printed "Checking … (Ctrl-C stops the check
at once)…" and then refused the level (the rtipy firmware cannot dim an LED): the
announcement promised a check that never began. Validate first, then announce.
"""

from __future__ import annotations

from pathlib import Path

from conftest import CONFIGS, said
from typer.testing import CliRunner

from rti_rig.cli import app

runner = CliRunner()


def test_a_refused_intensity_is_said_without_announcing_a_check() -> None:
    r = runner.invoke(app, ["check", str(CONFIGS / "emulated_rtipy.toml"), "--intensity", "0.5"])
    words = said(r)
    assert r.exit_code == 2 and "Traceback" not in words, words
    assert "--intensity 0.5 cannot be used on this dome" in words, words
    assert "Checking" not in words, words


def test_a_config_error_is_said_without_announcing_a_check(tmp_path: Path) -> None:
    cfg = tmp_path / "arm.toml"
    text = (CONFIGS / "virtual_arm.toml").read_text()
    cfg.write_text(text.replace("speed_deg_s = 60.0", "speed_deg_s = -1.0"))
    r = runner.invoke(app, ["check", str(cfg)])
    words = said(r)
    assert r.exit_code == 2 and "Traceback" not in words, words
    assert "speed_deg_s" in words and "Checking" not in words, words


def test_a_usable_check_is_announced_first() -> None:
    r = runner.invoke(app, ["check", str(CONFIGS / "virtual_arm.toml")])
    words = said(r)
    assert r.exit_code == 0, words
    assert r.output.startswith("Checking "), words
    assert "(Ctrl-C stops the check at once)…" in words, words
